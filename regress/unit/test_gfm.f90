!> Unit test of the ghost-fluid modules (modules/gfm, manual/interfaces.md):
!> (1) both probes reproduce a linear field exactly (1e-12) where their stencils are full, in
!> 2D and 3D; the least-squares probe still does with only a corner of real cells, and with
!> real cells on one grid line it takes the wider stencil; (2) an MVI ghost of a random
!> stressed state: the traction of the mean of image and ghost on the surface is zero
!> (sigma n = 0 to 1e-12 relative), J1 = tr S of the ghost is zero to round-off, density,
!> pressure and velocity are extended; (3) an MRI ghost: the mean normal velocity is the
!> wall's, the tangential velocity is extended, the normal stress is continuous and the
!> shear traction of the mean is zero; (4) the conservation fix's kernels (m_gfm_conserve)
!> on an axisymmetric block cut by a slanted surface: the content of a uniform state is its
!> density times the volume fractions' sum, and after a fix with factor fm and energy
!> coefficients the measured mass moves by (fm - 1) times the surface mass and the energy by
!> what the coefficients say (1e-12), with velocity and specific stress unchanged; (5) a
!> void's level set following the content (m_gfm_cut_close's cut_follow, theory.md 7c-7d): a
!> cut cell whose centre lies in the void is made the material's (phi = 0.01 h) when its
!> content fills it at its state's density, and only moved towards its content when not;
!> (6) the cut-cell update's small-cell groups (m_gfm_cut_cells' group_roots): a cell in
!> debt joins a neighbour that is not small, a sheet of small cells joins its highest cell,
!> and two blocks that share a side form every group their interiors read as one block over
!> the whole field does; (7) the mixing of small cells that no group holds (mix_lonely): the
!> content kept, a lonely cell moved towards its ring, two blocks bit for bit as one; (8) the
!> sound-speed test of a content (m_gfm_cut_close's content_sounds), which decides when a cut
!> cell's content is mixed or stranded: aluminium at rest, or moving with its kinetic energy
!> all in its total, sounds; the same content with e = -1.5e7 J/kg (the rod_plate_2d slivers)
!> sounds at no density from 0.5 to 1.15 rho0 (and does at 1.5); no mass or density: never.
program test_gfm
  use m_kinds, only: wp
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_done, int_text
  use m_gfm_probe, only: probe_trilinear, probe_least_squares
  use m_gfm_mvi, only: gfm_mvi
  use m_gfm_mri, only: gfm_mri
  use m_gfm_conserve, only: content_block, fix_block, n_content
  use m_layout, only: layout_t, layout_init, cell_volume
  use m_state, only: n_solid, i_rho, i_mx, i_my, i_en, i_sxx
  use m_blocks, only: block_t
  use m_levelset_bodies, only: ls_set_t, ls_void
  use m_gfm_cut_close, only: cut_follow, content_sounds
  use m_eos, only: eos_t, eos_mie_gruneisen, eos_prepare
  use m_gfm_cut_cells, only: group_roots, ring, debt_mark, mix_lonely
  implicit none
  call comm_init()
  call check_start('test_gfm', show_passes=.true.)
  call check_probes(2)
  call check_probes(3)
  call check_classes(2)
  call check_classes(3)
  call check_conserve()
  call check_follow()
  call check_groups()
  call check_lonely()
  call check_sounds()
  call check_done()

contains

  !> Two cut cells at fraction 0.9 with their centres 0.2 h inside a void: A's content fills
  !> it at its state's density (2000 kg/m^3), B's half of it. A is closed at once; B's level
  !> set moves towards its content (the void grows there) and its centre stays in the void.
  !> Before 2026-12-06 A too was only moved, by 0.025 h, and kept a ghost state at its faces.
  subroutine check_follow()
    integer, parameter :: n = 8, ils = 10
    type(block_t) :: blk
    type(ls_set_t) :: ls
    real(wp) :: alpha(n, n, 1), crho(n, n, 1), h
    integer :: ng(3)
    call layout_init(blk%lay, 2, [n, n, 1], [n, n, 1], [0.0_wp, 0.0_wp, 0.0_wp], &
      [1.0e-6_wp * n, 1.0e-6_wp * n, 1.0_wp], [.false., .false., .false.], .false.)
    blk%n = [n, n, 1]
    ng = blk%lay%ng
    allocate(blk%q(1-ng(1):n+ng(1), 1-ng(2):n+ng(2), 1:1, ils + 1))
    h = 1.0e-6_wp
    blk%q = 0.0_wp
    blk%q(:, :, :, ils + 1) = 3.0_wp * h      ! the material, far from the void
    blk%q(:, :, :, i_rho) = 2000.0_wp
    alpha = 1.0_wp
    crho = 2000.0_wp
    ls%n = 1
    ls%kind = [ls_void]
    ! cell A (3, 3): content fills it; cell B (6, 6): half full
    alpha(3, 3, 1) = 0.9_wp
    alpha(6, 6, 1) = 0.9_wp
    blk%q(3, 3, 1, ils + 1) = -0.2_wp * h
    blk%q(6, 6, 1, ils + 1) = -0.2_wp * h
    crho(6, 6, 1) = 1000.0_wp
    call cut_follow(blk, ils, 0, ls, alpha, crho, 1.0_wp)
    call check('follow: a cut cell its content fills is made the material''s (phi = 0.01 h)', &
      abs(blk%q(3, 3, 1, ils + 1) - 0.01_wp * h) < 1.0e-12_wp * h)
    call check('follow: a half-filled cut cell moves towards its content, centre still ' // &
      'in the void', &
      blk%q(6, 6, 1, ils + 1) < -0.2_wp * h)
    call check('follow: full cells of the material far from the void untouched', &
      abs(blk%q(1, 1, 1, ils + 1) - 3.0_wp * h) < 1.0e-12_wp * h)
  end subroutine check_follow

  !> The small-cell groups on a 16 x 8 field of fractions with sheets of small cells, cells
  !> that are not small, empty cells and cells in debt (debt_mark, as m_gfm_cut marks
  !> them): in one block over the whole field, then in two blocks of 8 x 8 side by side
  !> (halo of 3 cells of fractions, as the update has); for each interior cell of each half
  !> its root and every ring neighbour's membership of that root are the whole field's.
  subroutine check_groups()
    integer, parameter :: nx = 16, ny = 8, e = 3
    type(layout_t) :: lay
    real(wp) :: f(1-e:nx+e, 1-e:ny+e, 1)
    integer, allocatable :: rg(:, :, :, :), rh(:, :, :, :)
    integer :: i, j, h, o, r(3), nb(3, 26), nl, l, bad
    call layout_init(lay, 2, [nx, ny, 1], [8, 8, 1], [0.0_wp, 0.0_wp, 0.0_wp], &
      [1.0_wp, 0.5_wp, 1.0_wp], [.false., .false., .false.], .false.)
    call sheet_field(f)
    ! the whole field
    call group_roots(lay, [0, 0, 0], [nx, ny, 1], [e, e, 0], f, 0.5_wp, rg)
    call check('groups: a cell in debt joins its neighbour that is not small', &
      all(rg(:, 11, 2, 1) == [12, 2, 1]))
    r = rg(:, 4, 2, 1)
    call check('groups: a cell in debt in a sheet of small cells joins the sheet''s root', &
      .not. all(r == [4, 2, 1]) .and. f(r(1), r(2), 1) > 0.0_wp)
    call check('groups: the root of small cells is no member', all(rg(:, r(1), r(2), 1) == r))
    call check('groups: a cell in debt on the shared side joins the highest cell beside it', &
      all(rg(:, 8, 6, 1) == [9, 6, 1]))
    call check('groups: small cells join the highest of their ring (faces and corners)', &
      all(rg(:, 9, 7, 1) == [9, 6, 1]) .and. all(rg(:, 2, 8, 1) == [3, 7, 1]) .and. &
      all(rg(:, 5, 5, 1) == [6, 4, 1]) .and. all(rg(:, 3, 7, 1) == [3, 7, 1]))
    ! the two halves
    bad = 0
    do h = 0, 1
      o = 8 * h
      call group_roots(lay, [o, 0, 0], [8, ny, 1], [e, e, 0], &
        f(o + 1 - e:o + 8 + e, :, :), 0.5_wp, rh)
      do j = 1, ny
        do i = 1, 8
          r = rg(:, o + i, j, 1)
          if (.not. all(rh(:, i, j, 1) + [o, 0, 0] == r)) bad = bad + 1
          call ring(2, r, nb, nl)
          do l = 1, nl
            if (any(nb(1:2, l) < 1) .or. nb(1, l) > nx .or. nb(2, l) > ny) cycle
            if (nb(1, l) - o < lbound(rh, 2) .or. nb(1, l) - o > ubound(rh, 2)) then
              bad = bad + 1
              cycle
            end if
            if (all(rg(:, nb(1, l), nb(2, l), 1) == r) .neqv. &
              all(rh(:, nb(1, l) - o, nb(2, l), 1) + [o, 0, 0] == r)) bad = bad + 1
          end do
        end do
      end do
    end do
    call check('groups: two blocks form every group their interiors read as one block ' // &
      'does (' // int_text(bad) // ' differences)', bad == 0)
  end subroutine check_groups

  !> The 16 x 8 field of fractions of check_groups: diagonal sheets of small cells, a patch
  !> of cells that are not small, cells in debt (debt_mark), zero beyond the domain.
  subroutine sheet_field(f)
    real(wp), intent(out) :: f(-2:, -2:, :)
    integer :: i, j
    f = 0.0_wp
    do j = 1, 8
      do i = 1, 16
        ! diagonal sheets of small cells (0.05 .. 0.45), a block of cells that are not small
        if (mod(i + j, 5) == 0) f(i, j, 1) = 0.05_wp + 0.4_wp * real(mod(7 * i + 3 * j, 11), wp) &
          / 10.0_wp
        if (mod(i + j, 5) == 1 .and. mod(i, 3) == 0) f(i, j, 1) = 0.2_wp
        if (i >= 12 .and. j <= 3) f(i, j, 1) = 0.8_wp
      end do
    end do
    f(11, 2, 1) = debt_mark       ! in debt beside the cells that are not small
    f(4, 2, 1) = debt_mark        ! in debt in a sheet
    f(8, 6, 1) = debt_mark        ! in debt on the blocks' shared side
    f(9, 6, 1) = 0.45_wp     ! the highest of its ring
  end subroutine sheet_field

  !> (8) content_sounds on aluminium (rho0 2790, c0 5328 m/s, s 1.338, Gamma 2): contents per
  !> unit volume (rho, rho u, rho v, rho w, rho E).
  subroutine check_sounds()
    type(eos_t) :: al
    real(wp) :: rest(5), moving(5), spent(5), f
    logical :: any_sound, sounds, massless
    integer :: m
    al = eos_t(kind=eos_mie_gruneisen, rho0=2790.0_wp, c0=5328.0_wp, s=1.338_wp, &
      gruneisen=2.0_wp, cv=885.0_wp, T0=298.0_wp)
    call eos_prepare(al)
    rest = [2790.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    moving = [27.9_wp, 27.9_wp * 1000.0_wp, 0.0_wp, 0.0_wp, 0.5_wp * 27.9_wp * 1000.0_wp**2]
    spent = moving
    spent(5) = moving(5) - 27.9_wp * 1.5e7_wp
    call check('content_sounds: aluminium at rest sounds at rho0', &
      content_sounds(al, 2790.0_wp, rest))
    call check('content_sounds: a sliver at 1000 m/s with e = 0 sounds at rho0', &
      content_sounds(al, 2790.0_wp, moving))
    any_sound = .false.
    do m = 0, 20
      f = 0.5_wp * 2.3_wp**(real(m, wp) / 20.0_wp)
      sounds = content_sounds(al, f * 2790.0_wp, spent)
      any_sound = any_sound .or. sounds
    end do
    call check('content_sounds: e = -1.5e7 J/kg sounds at no density in 0.5-1.15 rho0', &
      .not. any_sound)
    ! (compressed beyond about 1.18 rho0 the Hugoniot's stiffness gives it a sound speed)
    call check('content_sounds: ... and does at 1.5 rho0', &
      content_sounds(al, 1.5_wp * 2790.0_wp, spent))
    sounds = content_sounds(al, 0.0_wp, rest)
    massless = content_sounds(al, 2790.0_wp, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp])
    call check('content_sounds: no density, no mass: never', .not. (sounds .or. massless))
  end subroutine check_sounds

  !> The mixing of small cells that no group holds (m_gfm_cut_cells' mix_lonely) on
  !> check_groups' field, axisymmetric (cell volumes grow with r), with a content of two
  !> variables that differs from cell to cell: the total content times volume is kept (1e-13
  !> relative); a lonely cell whose content is far from its neighbours' moves towards them;
  !> two blocks side by side give every interior cell the contents of one block over the
  !> whole field, bit for bit.
  subroutine check_lonely()
    integer, parameter :: nx = 16, ny = 8, e = 3, g = 4
    type(layout_t) :: lay
    real(wp) :: f(1-e:nx+e, 1-e:ny+e, 1), cq(1-g:nx+g, 1-g:ny+g, 1, 2), c(nx, ny, 1, 2)
    real(wp) :: ch(8, ny, 1, 2), before(2), after(2), v
    integer, allocatable :: rg(:, :, :, :), rh(:, :, :, :)
    integer :: i, j, h, o, count, bad
    call layout_init(lay, 2, [nx, ny, 1], [8, 8, 1], [0.0_wp, 0.0_wp, 0.0_wp], &
      [1.0_wp, 0.5_wp, 1.0_wp], [.false., .false., .false.], .true.)
    call sheet_field(f)
    cq = 0.0_wp
    do j = 1, ny
      do i = 1, nx
        if (.not. f(i, j, 1) > 0.0_wp) cycle
        cq(i, j, 1, 1) = f(i, j, 1) * (1000.0_wp + 100.0_wp * real(mod(5 * i + 2 * j, 7), wp))
        cq(i, j, 1, 2) = f(i, j, 1) * 1.0e5_wp * real(1 + mod(3 * i + j, 4), wp)
      end do
    end do
    ! a lonely cell of the sheet far from its ring: ten times the content
    cq(5, 5, 1, :) = 10.0_wp * cq(5, 5, 1, :)
    call group_roots(lay, [0, 0, 0], [nx, ny, 1], [e, e, 0], f, 0.5_wp, rg)
    c = cq(1:nx, 1:ny, :, :)
    count = 0
    call mix_lonely(lay, [0, 0, 0], [e, e, 0], f, f, rg, 0.5_wp, cq, &
      reshape([1, 1, 1, nx, ny, 1], [2, 3], order=[2, 1]), c, count)
    before = 0.0_wp
    after = 0.0_wp
    do i = 1, nx
      v = cell_volume(lay, [0, 0, 0], i)
      before = before + [sum(cq(i, 1:ny, 1, 1)), sum(cq(i, 1:ny, 1, 2))] * v
      after = after + [sum(c(i, :, 1, 1)), sum(c(i, :, 1, 2))] * v
    end do
    call check('lonely: ' // int_text(count) // ' lonely cells mixed, the content kept', &
      count > 0 .and. all(abs(after - before) < 1.0e-13_wp * abs(before)))
    call check('lonely: a lonely cell with ten times its ring''s content gives most away', &
      c(5, 5, 1, 1) < 0.5_wp * cq(5, 5, 1, 1) .and. c(5, 5, 1, 1) > 0.0_wp)
    bad = 0
    do h = 0, 1
      o = 8 * h
      call group_roots(lay, [o, 0, 0], [8, ny, 1], [e, e, 0], f(o + 1 - e:o + 8 + e, :, :), &
        0.5_wp, rh)
      ch = cq(o + 1:o + 8, 1:ny, :, :)
      call mix_lonely(lay, [o, 0, 0], [e, e, 0], f(o + 1 - e:o + 8 + e, :, :), &
        f(o + 1 - e:o + 8 + e, :, :), rh, 0.5_wp, cq(o + 1 - g:o + 8 + g, :, :, :), &
        reshape([1, 1, 1, 8, ny, 1], [2, 3], order=[2, 1]), ch, count)
      bad = bad + count_differences(ch, c(o + 1:o + 8, :, :, :))
    end do
    call check('lonely: two blocks mix every interior cell as one block does (' // &
      int_text(bad) // ' differences)', bad == 0)
  end subroutine check_lonely

  !> the entries of a and b that differ (bit for bit)
  integer function count_differences(a, b) result(nd)
    real(wp), intent(in) :: a(:, :, :, :), b(:, :, :, :)
    nd = count(a < b .or. a > b)
  end function count_differences

  subroutine check_probes(nd)
    integer, intent(in) :: nd
    integer, parameter :: n = 6
    real(wp) :: w(-1:n, -1:n, -1:n, 2), s(3), val(2), bval(2), c(3), exact(2)
    logical :: isreal(-1:n, -1:n, -1:n), complete
    integer :: lo(3), hi(3), i, j, k, npts
    character(len=8) :: tag
    write(tag, '(i0,a)') nd, 'D'
    lo = -1
    hi = n
    if (nd < 3) then
      lo(3) = 1
      hi(3) = 1
    end if
    c = [0.7_wp, -1.3_wp, 2.1_wp]
    if (nd < 3) c(3) = 0.0_wp
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          w(i, j, k, 1) = 3.0_wp + dot_product(c, real([i, j, k], wp))
          w(i, j, k, 2) = -1.0_wp + 0.5_wp * dot_product(c, real([i, j, k], wp))
        end do
      end do
    end do
    s = [2.3_wp, 3.6_wp, 1.0_wp]
    if (nd == 3) s(3) = 2.45_wp
    exact = [3.0_wp + dot_product(c, s), -1.0_wp + 0.5_wp * dot_product(c, s)]
    isreal = .true.
    call probe_trilinear(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, complete)
    call check(trim(tag) // ' trilinear exact for a linear field, full stencil', &
      complete .and. maxval(abs(val - exact)) < 1.0e-12_wp)
    call probe_least_squares(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, npts)
    call check(trim(tag) // ' least squares exact for a linear field, full stencil', &
      npts == 3**nd .and. maxval(abs(val - exact)) < 1.0e-12_wp)
    ! only the cells below and left of the point are real: a corner
    isreal = .false.
    isreal(:2, :3, :) = .true.
    call probe_trilinear(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, complete)
    call check(trim(tag) // ' trilinear reports an incomplete stencil at a corner', &
      .not. complete)
    call probe_least_squares(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, npts)
    call check(trim(tag) // ' least squares exact at a corner (fewer real cells)', &
      npts > 0 .and. npts < 5**nd .and. maxval(abs(val - exact)) < 1.0e-12_wp)
    ! the ghost fill's form (bounded_from = 1): a point beyond the corner's real cells, where
    ! the linear fit extrapolates out of their range; bounded, each variable is the fit
    ! clamped to the range of the real cells in the fit
    s(1:2) = [3.4_wp, 4.4_wp]
    if (nd == 3) s(3) = 3.4_wp
    isreal = .false.
    isreal(:2, :3, :2) = .true.
    exact = [3.0_wp + dot_product(c, s), -1.0_wp + 0.5_wp * dot_product(c, s)]
    call probe_least_squares(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, bval, npts, bounded_from=1)
    call check(trim(tag) // ' bounded least squares = the fit within its cells'' range', &
      npts > 0 .and. maxval(abs(bval - clamp_to_real(nd, w, isreal, s, exact))) < 1.0e-12_wp &
      .and. maxval(abs(bval - exact)) > 0.1_wp)
    ! real cells on one line of i only (a surface along a grid line): the 3-stencil is
    ! degenerate, the 5-stencil is not
    isreal = .false.
    isreal(:1, :, :) = .true.
    s(1) = 1.7_wp
    exact = [3.0_wp + dot_product(c, s), -1.0_wp + 0.5_wp * dot_product(c, s)]
    call probe_least_squares(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, npts)
    call check(trim(tag) // ' least squares exact with real cells on one grid line', &
      npts > 0 .and. maxval(abs(val - exact)) < 1.0e-11_wp)
    isreal = .false.
    call probe_least_squares(nd, lo, hi, w(lo(1):, lo(2):, lo(3):, :), &
      isreal(lo(1):, lo(2):, lo(3):), s, val, npts)
    call check(trim(tag) // ' least squares reports no real cell', npts == 0)
  end subroutine check_probes

  !> x clamped, variable by variable, to the range of the real cells within two cells of the
  !> point's nearest cell (a corner's fit takes the 5^nd stencil: its 3^nd real cells lie on
  !> one line or plane)
  function clamp_to_real(nd, w, isreal, s, x) result(y)
    integer, intent(in) :: nd
    real(wp), intent(in) :: w(-1:, -1:, -1:, :), s(3), x(2)
    logical, intent(in) :: isreal(-1:, -1:, -1:)
    real(wp) :: y(2), wlo(2), whi(2)
    integer :: ic(3), a, b, e, top(3)
    ic = 1
    ic(1:nd) = nint(s(1:nd))
    top = ubound(isreal)
    wlo = huge(1.0_wp)
    whi = -huge(1.0_wp)
    do e = max(ic(3) - 2, -1), min(ic(3) + 2, top(3))
      if (nd < 3 .and. e /= 1) cycle
      do b = max(ic(2) - 2, -1), min(ic(2) + 2, top(2))
        do a = max(ic(1) - 2, -1), min(ic(1) + 2, top(1))
          if (.not. isreal(a, b, e)) cycle
          wlo = min(wlo, w(a, b, e, :))
          whi = max(whi, w(a, b, e, :))
        end do
      end do
    end do
    y = min(max(x, wlo), whi)
  end function clamp_to_real

  subroutine check_classes(nd)
    integer, intent(in) :: nd
    real(wp) :: wi(13), wg(13), nrm(3), sig_i(3, 3), sig_g(3, 3), t(3), vb(3), un
    real(wp) :: scale
    character(len=8) :: tag
    write(tag, '(i0,a)') nd, 'D'
    nrm = [0.6_wp, 0.8_wp, 0.0_wp]
    if (nd == 3) nrm = [0.48_wp, 0.64_wp, 0.6_wp]
    wi = [8930.0_wp, 120.0_wp, -35.0_wp, 0.0_wp, 1.3e9_wp, 2.1e8_wp, -0.7e8_wp, -1.4e8_wp, &
      0.9e8_wp, 0.3e8_wp, -0.5e8_wp, 0.4_wp, 1.0e3_wp]
    if (nd == 3) wi(4) = 17.0_wp
    scale = 1.3e9_wp
    call gfm_mvi(nd, nrm, wi, wg)
    sig_i = stress(wi)
    sig_g = stress(wg)
    t = matmul(0.5_wp * (sig_i + sig_g), nrm)
    call check(trim(tag) // ' MVI: traction of the mean state on the surface is zero', &
      norm2(t) < 1.0e-12_wp * scale)
    call check(trim(tag) // ' MVI: J1 of the ghost deviator is zero', &
      abs(wg(6) + wg(7) + wg(8)) < 1.0e-12_wp * scale)
    call check(trim(tag) // ' MVI: density, pressure, velocity, eps_p extended', &
      maxval(abs(wg(1:5) - wi(1:5))) <= 0.0_wp .and. maxval(abs(wg(12:13) - wi(12:13))) <= 0.0_wp)
    vb = [3.0_wp, -2.0_wp, 0.0_wp]
    call gfm_mri(nd, nrm, vb, wi, wg)
    un = dot_product(0.5_wp * (wi(2:4) + wg(2:4)), nrm)
    call check(trim(tag) // ' MRI: mean normal velocity is the wall''s', &
      abs(un - dot_product(vb, nrm)) < 1.0e-12_wp * 100.0_wp)
    call check(trim(tag) // ' MRI: tangential velocity extended', norm2((wg(2:4) - wi(2:4)) &
      - dot_product(wg(2:4) - wi(2:4), nrm) * nrm) < 1.0e-12_wp * 100.0_wp)
    sig_i = stress(wi)
    sig_g = stress(wg)
    t = matmul(0.5_wp * (sig_i + sig_g), nrm)
    call check(trim(tag) // ' MRI: normal stress continuous, no shear traction', &
      abs(dot_product(t, nrm) - dot_product(matmul(sig_i, nrm), nrm)) < 1.0e-12_wp * scale &
      .and. norm2(t - dot_product(t, nrm) * nrm) < 1.0e-12_wp * scale)
    call check(trim(tag) // ' MRI: J1 of the ghost deviator is zero', &
      abs(wg(6) + wg(7) + wg(8) - sum(wi(6:8))) < 1.0e-12_wp * scale)
  end subroutine check_classes

  subroutine check_conserve()
    type(layout_t) :: lay
    real(wp), allocatable :: q(:, :, :, :), phi(:, :, :)
    real(wp) :: c0(n_content), c1(n_content), h, frac, r, z, fm, ah, am, heat0
    integer :: i, j
    call layout_init(lay, 2, [8, 8, 1], [8, 8, 1], [0.0_wp, 0.0_wp, 0.0_wp], &
      [1.0_wp, 1.0_wp, 1.0_wp], [.false., .false., .false.], .true.)
    allocate(q(-3:12, -3:12, 1:1, n_solid), phi(-3:12, -3:12, 1:1))
    h = 0.125_wp
    q = 0.0_wp
    q(:, :, :, i_rho) = 2.0_wp
    q(:, :, :, i_mx) = 2.0_wp * 3.0_wp
    q(:, :, :, i_my) = -2.0_wp * 1.0_wp
    q(:, :, :, i_en) = 2.0_wp * (7.0_wp + 0.5_wp * 10.0_wp)
    q(:, :, :, i_sxx) = 2.0_wp * 0.25_wp
    frac = 0.0_wp
    do j = -3, 12
      do i = -3, 12
        r = (real(i, wp) - 0.5_wp) * h
        z = (real(j, wp) - 0.5_wp) * h
        phi(i, j, 1) = (0.6_wp * r + 0.8_wp * z) - 0.55_wp
        if (i >= 1 .and. i <= 8 .and. j >= 1 .and. j <= 8 .and. phi(i, j, 1) < 0.5_wp * h) &
          frac = frac + min(1.0_wp, 0.5_wp - phi(i, j, 1) / h) * h * h * 8.0_wp &
          * atan(1.0_wp) * r
      end do
    end do
    call content_block(lay, [0, 0, 0], q, phi, h, 2.0_wp * h, c0)
    call check('fix: mass of a uniform state = rho x sum of volume fractions', &
      abs(c0(1) - 2.0_wp * frac) < 1.0e-12_wp * c0(1))
    call check('fix: internal energy share = rho e of the surface mass', &
      abs(c0(5) - 7.0_wp * c0(3)) < 1.0e-12_wp * c0(5))
    fm = 0.97_wp
    ah = -0.02_wp
    am = 0.0_wp
    heat0 = c0(5)
    call fix_block(lay, q, phi, 2.0_wp * h, fm, ah, am)
    call content_block(lay, [0, 0, 0], q, phi, h, 2.0_wp * h, c1)
    call check('fix: mass moves by (fm - 1) x surface mass', &
      abs(c1(1) - c0(1) - (fm - 1.0_wp) * c0(3)) < 1.0e-12_wp * c0(1))
    call check('fix: energy moves by the scaling and a_heat x surface heat', &
      abs(c1(2) - c0(2) - (fm - 1.0_wp) * c0(4) - ah * fm * heat0) < 1.0e-12_wp * c0(2))
    call check('fix: velocity and specific stress unchanged', &
      all(abs(q(1:8, 1:8, 1, i_mx) / q(1:8, 1:8, 1, i_rho) - 3.0_wp) < 1.0e-13_wp) .and. &
      all(abs(q(1:8, 1:8, 1, i_sxx) / q(1:8, 1:8, 1, i_rho) - 0.25_wp) < 1.0e-13_wp))
    call fix_block(lay, q, phi, 2.0_wp * h, 1.0_wp, 0.0_wp, 0.5_wp)
    call content_block(lay, [0, 0, 0], q, phi, h, 2.0_wp * h, c0)
    call check('fix: a_mass adds a_mass x surface mass to the energy', &
      abs(c0(2) - c1(2) - 0.5_wp * c1(3)) < 1.0e-12_wp * c0(2))
  end subroutine check_conserve

  pure function stress(w) result(sig)
    real(wp), intent(in) :: w(:)
    real(wp) :: sig(3, 3)
    integer :: d
    sig = reshape([w(6), w(9), w(11), w(9), w(7), w(10), w(11), w(10), w(8)], [3, 3])
    do d = 1, 3
      sig(d, d) = sig(d, d) - w(5)
    end do
  end function stress

end program test_gfm
