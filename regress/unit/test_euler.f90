!> Unit test of m_euler's right-hand side, on one block with its halo filled here:
!> (1) free-stream preservation: a uniform state (gas, and a solid with a uniform stress
!>     deviator, plastic strain and stored work) gives rhs = 0 to round-off (1e-12 of
!>     fluxes of size 1 over dx) for every reconstruction (eno1, eno2, eno3, weno5) and
!>     flux (LLF, HLLC; solids LLF with LLF or upwind scalars), in 1D, 2D and 3D, and in
!>     axisymmetry, where the hoop stress p / r balances the r-weighted radial pressure
!>     flux (at rest radially, S_rr = S_theta theta and no S_rz, as equilibrium needs);
!> (2) flux balance of a smooth 1D pulse between two outflow sides: the sum of rhs dx over
!>     the cells is what crossed the two sides, the mass and energy rates that euler_rhs
!>     reports (bflux), and at first order the momentum rate is the difference of the
!>     physical fluxes rho u^2 + p of the two end cells;
!> (3) a conservative update: 30 third-order Runge-Kutta steps (rk_stage_update) of a
!>     periodic 1D and 2D problem (gas and solid) keep the totals of mass, momentum and
!>     energy to 1e-13 of their size;
!> (4) a body's surface (a level set: real cells on one side, the phase's ghosts on the
!>     other) with the material moving from the ghosts into the real cells: the real cell
!>     at the surface keeps its plastic strain (rhs of rho eps_p = eps_p times rhs of rho),
!>     and the ghost beside it, whose plastic strain is a millionth of the real cell's, keeps
!>     rho eps_p >= 0 over a step at the time step's limit (its scalars leave it at its own
!>     value, not the real cell's), on either side of the body.
!> (5) boxes of the block (a body's cells near its surface, tile by tile, m_gfm_stage): the
!>     rates of their cells are those of the whole block to the bit and every other cell's
!>     is 0, for gas and solid, with a surface, in 3D and in axisymmetry, for a box inside
!>     the block, one at its sides, and the two together.
!> The state is of size 1 (rho, p, c, |S| of order 1): round-off is then 1e-16 of it.
!> euler_rhs is called in one place (compute_rhs), so a change of its arguments is one edit.
program test_euler
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_ideal_gas, eos_energy
  use m_yield, only: strength_t, strength_elastic
  use m_reconstruct, only: scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5
  use m_flux, only: flux_kind_llf, flux_kind_hllc, scalar_flux_llf, scalar_flux_upwind
  use m_runge_kutta, only: rk_stage_update, euler_max_rate
  use m_euler, only: euler_work_t, euler_work_init, euler_rhs, numerics_t
  use m_layout, only: layout_t, layout_init, block_view
  use m_state, only: n_euler, n_solid, i_rho, i_mx, i_mz, i_en, i_sxx, i_syy, i_szz, &
    i_sxy, i_syz, i_sxz, i_epsp, i_wcold
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_error, check_close, check_done
  implicit none
  integer, parameter :: schemes(4) = [scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5]
  character(len=5), parameter :: scheme_names(4) = ['eno1 ', 'eno2 ', 'eno3 ', 'weno5']
  real(wp), parameter :: tol_rhs = 1.0e-12_wp, tol_total = 1.0e-13_wp
  type(eos_t) :: gas
  type(strength_t) :: solid, nostrength
  integer :: s, nd
  call comm_init()
  call check_start('test_euler')
  gas = eos_t(kind=eos_ideal_gas, gamma=1.4_wp, cv=1.0_wp)
  solid = strength_t(model=strength_elastic, g=1.0_wp)

  do s = 1, 4
    do nd = 1, 3
      call free_stream(nd, .false., s, flux_kind_llf, scalar_flux_llf, .false.)
      call free_stream(nd, .false., s, flux_kind_hllc, scalar_flux_llf, .false.)
      call free_stream(nd, .true., s, flux_kind_llf, scalar_flux_llf, .false.)
      call free_stream(nd, .true., s, flux_kind_llf, scalar_flux_upwind, .false.)
    end do
    call free_stream(2, .false., s, flux_kind_llf, scalar_flux_llf, .true.)
    call free_stream(2, .false., s, flux_kind_hllc, scalar_flux_llf, .true.)
    call free_stream(2, .true., s, flux_kind_llf, scalar_flux_upwind, .true.)
    call flux_balance(s)
    call surface_scalars(s, 1)
    call surface_scalars(s, -1)
  end do
  call periodic_update(1, .false., scheme_weno5)
  call periodic_update(1, .true., scheme_eno3)
  call periodic_update(2, .false., scheme_eno2)
  call periodic_update(2, .true., scheme_weno5)
  call box_rates(3, .false., .false.)
  call box_rates(3, .true., .false.)
  call box_rates(2, .true., .true.)
  call check_done()

contains

  !> The one call of euler_rhs: a block without walls, at offset 0 of its layout; the
  !> rates that crossed the domain's sides come back in bflux.
  subroutine compute_rhs(lay, st, scheme, flux, scalar_flux, q, rhs, work, bflux, bigphi, &
      boxes)
    type(layout_t), intent(in) :: lay
    type(strength_t), intent(in) :: st
    integer, intent(in) :: scheme, flux, scalar_flux
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(out) :: rhs(:, :, :, :)
    type(euler_work_t), intent(inout) :: work
    real(wp), intent(out) :: bflux(2)
    !> the phase's composite level set (< 0 where its cells are real), when it has a surface
    real(wp), intent(in), optional :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    integer, intent(in), optional :: boxes(:, :, :)   !< the cells whose rates are made
    logical :: wall(2, 3), failed
    real(wp) :: vwall(2, 3)
    integer :: nfallback
    type(numerics_t) :: num
    num = numerics_t(scheme=scheme, flux=flux, scalar_flux=scalar_flux)
    wall = .false.
    vwall = 0.0_wp
    nfallback = 0
    failed = .false.
    call euler_rhs(lay, gas, st, num, q, rhs, [0, 0, 0], wall, vwall, work, nfallback, &
      failed, bigphi, boxes=boxes)
    call check('euler_rhs: no face fell back, the stage went on', nfallback == 0 .and. &
      .not. failed)
    bflux = work%bflux
  end subroutine compute_rhs

  !> A layout of one block over [lo, lo + 1]^nd (cells per direction from ncell) and its view.
  subroutine one_block(nd, ncell, periodic, axisymmetric, lay)
    integer, intent(in) :: nd, ncell(3)
    logical, intent(in) :: periodic, axisymmetric
    type(layout_t), intent(out) :: lay
    type(layout_t) :: full
    real(wp) :: lo(3)
    lo = [0.0_wp, -0.5_wp, 0.25_wp]
    call layout_init(full, nd, ncell, ncell, lo, lo + 1.0_wp, [periodic, periodic, periodic], &
      axisymmetric)
    lay = block_view(full, 1)
  end subroutine one_block

  !> Conserved variables of one cell from rho, u(3), p and (solid) the deviator S(6) in
  !> the order xx, yy, zz, xy, yz, xz, eps_p and w_c.
  subroutine conserved(nv, rho, u, p, sdev, epsp, wc, qc)
    integer, intent(in) :: nv
    real(wp), intent(in) :: rho, u(3), p, sdev(6), epsp, wc
    real(wp), intent(out) :: qc(nv)
    real(wp) :: e(1)
    call eos_energy(gas, 1, [rho], [p], e)
    qc(i_rho) = rho
    qc(i_mx:i_mz) = rho * u
    qc(i_en) = rho * (e(1) + 0.5_wp * sum(u**2))
    if (nv == n_euler) return
    qc([i_sxx, i_syy, i_szz, i_sxy, i_syz, i_sxz]) = rho * sdev
    qc(i_epsp) = rho * epsp
    qc(i_wcold) = rho * wc
  end subroutine conserved

  subroutine free_stream(nd, with_strength, is, flux, scalar_flux, axisymmetric)
    integer, intent(in) :: nd, is, flux, scalar_flux
    logical, intent(in) :: with_strength, axisymmetric
    type(layout_t) :: lay
    type(euler_work_t) :: work
    real(wp), allocatable :: q(:, :, :, :), rhs(:, :, :, :)
    real(wp) :: u(3), sdev(6), qc(n_solid), bflux(2)
    integer :: nv, m
    character(len=:), allocatable :: tag
    nv = merge(n_solid, n_euler, with_strength)
    call one_block(nd, [12, 10, 8], .false., axisymmetric, lay)
    u = [0.3_wp, -0.2_wp, 0.15_wp]
    sdev = [0.12_wp, -0.05_wp, -0.07_wp, 0.04_wp, -0.03_wp, 0.02_wp]
    if (axisymmetric) then
      ! (r, z, theta): no radial or swirl velocity, S_rr = S_theta theta, no S_rz
      u = [0.0_wp, 0.3_wp, 0.0_wp]
      sdev = [0.05_wp, -0.1_wp, 0.05_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    end if
    call conserved(nv, 1.3_wp, u, 0.9_wp, sdev, 0.2_wp, 0.01_wp, qc)
    allocate(q(1-lay%ng(1):lay%bsize(1)+lay%ng(1), 1-lay%ng(2):lay%bsize(2)+lay%ng(2), &
      1-lay%ng(3):lay%bsize(3)+lay%ng(3), nv))
    allocate(rhs(lay%bsize(1), lay%bsize(2), lay%bsize(3), nv))
    do m = 1, nv
      q(:, :, :, m) = qc(m)
    end do
    call euler_work_init(lay, nv, work)
    if (with_strength) then
      call compute_rhs(lay, solid, schemes(is), flux, scalar_flux, q, rhs, work, bflux)
    else
      call compute_rhs(lay, nostrength, schemes(is), flux, scalar_flux, q, rhs, work, bflux)
    end if
    tag = 'free stream ' // trim(merge('axisymmetric ', 'cartesian    ', axisymmetric)) // &
      ' ' // achar(48 + nd) // 'D ' // merge('solid', 'gas  ', with_strength) // ' ' // &
      trim(scheme_names(is)) // ' ' // trim(merge('hllc', 'llf ', flux == flux_kind_hllc)) // &
      trim(merge(' upwind scalars', '               ', scalar_flux == scalar_flux_upwind)) // &
      ': max |rhs|'
    call check_error(tag, maxval(abs(rhs)), tol_rhs)
  end subroutine free_stream

  !> A smooth pulse in rho, u, p (and S) on 40 cells of [0, 1] between outflow sides (the
  !> halo holds copies of the end cells).
  subroutine pulse(lay, nv, q)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: nv
    real(wp), intent(out) :: q(1-lay%ng(1):, :, :, :)
    real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
    real(wp) :: x, b, qc(n_solid), sdev(6)
    integer :: i, n
    n = lay%bsize(1)
    do i = 1, n
      x = lay%lo(1) + (real(i, wp) - 0.5_wp) * lay%dx(1)
      b = exp(-40.0_wp * (x - 0.45_wp)**2)
      sdev = 0.1_wp * b * [1.0_wp, -0.4_wp, -0.6_wp, 0.3_wp, -0.2_wp, 0.1_wp]
      call conserved(nv, 1.0_wp + 0.5_wp * b + 0.1_wp * x, [0.4_wp + 0.3_wp * b, 0.1_wp, &
        -0.2_wp * x], 1.0_wp + 0.8_wp * b + 0.2_wp * sin(2.0_wp * pi * x), sdev, 0.3_wp * b, &
        0.02_wp * x, qc)
      q(i, 1, 1, :) = qc(1:nv)
    end do
    do i = 1, lay%ng(1)
      q(1 - i, 1, 1, :) = q(1, 1, 1, :)
      q(n + i, 1, 1, :) = q(n, 1, 1, :)
    end do
  end subroutine pulse

  subroutine flux_balance(is)
    integer, intent(in) :: is
    type(layout_t) :: lay
    type(euler_work_t) :: work
    real(wp), allocatable :: q(:, :, :, :), rhs(:, :, :, :)
    real(wp) :: bflux(2), total(n_solid), size_m, f1, fn
    integer :: nv, n
    character(len=:), allocatable :: tag
    logical :: with_strength
    do nv = n_euler, n_solid, n_solid - n_euler
      with_strength = nv == n_solid
      call one_block(1, [40, 1, 1], .false., .false., lay)
      n = lay%bsize(1)
      allocate(q(1-lay%ng(1):n+lay%ng(1), 1, 1, nv), rhs(n, 1, 1, nv))
      call pulse(lay, nv, q)
      call euler_work_init(lay, nv, work)
      if (with_strength) then
        call compute_rhs(lay, solid, schemes(is), flux_kind_llf, scalar_flux_upwind, q, rhs, &
          work, bflux)
      else
        call compute_rhs(lay, nostrength, schemes(is), flux_kind_hllc, scalar_flux_llf, q, &
          rhs, work, bflux)
      end if
      total(1:nv) = sum(rhs(:, 1, 1, :), dim=1) * lay%dx(1)
      tag = 'flux balance 1D ' // merge('solid ', 'gas   ', with_strength) // &
        trim(scheme_names(is)) // ': '
      size_m = sum(abs(rhs(:, 1, 1, i_rho))) * lay%dx(1) + abs(bflux(1))
      call check(tag // 'mass rate through the sides is reported', abs(bflux(1)) > 1.0e-3_wp)
      call check_close(tag // 'sum of rhs_rho dx = mass rate through the sides', total(i_rho), &
        bflux(1), tol_total * size_m)
      size_m = sum(abs(rhs(:, 1, 1, i_en))) * lay%dx(1) + abs(bflux(2))
      call check_close(tag // 'sum of rhs_E dx = energy rate through the sides', total(i_en), &
        bflux(2), tol_total * size_m)
      if (schemes(is) == scheme_eno1 .and. .not. with_strength) then
        ! first order: the side faces' states are the end cells', the flux the physical one
        f1 = q(1, 1, 1, i_mx)**2 / q(1, 1, 1, i_rho) + cell_pressure(q(1, 1, 1, :))
        fn = q(n, 1, 1, i_mx)**2 / q(n, 1, 1, i_rho) + cell_pressure(q(n, 1, 1, :))
        call check_close(tag // 'sum of rhs_mx dx = (rho u^2 + p)(cell 1) - (cell n)', &
          total(i_mx), f1 - fn, tol_total * (abs(f1) + abs(fn)))
      end if
      deallocate(q, rhs)
    end do
  end subroutine flux_balance

  !> Test (4): 40 cells of a solid moving at 0.4 towards its real half (side = 1: the real
  !> cells are 21..40, the ghosts 1..20; side = -1 the mirror image), eps_p 0.5 in the real
  !> cells and 5e-7 in the ghosts.
  subroutine surface_scalars(is, side)
    integer, intent(in) :: is, side
    type(layout_t) :: lay
    type(euler_work_t) :: work
    real(wp), allocatable :: q(:, :, :, :), rhs(:, :, :, :), bigphi(:, :, :)
    real(wp) :: bflux(2), qc(n_solid), sdev(6), dt, x
    integer :: i, n, g, real_cell, ghost_cell
    character(len=:), allocatable :: tag
    call one_block(1, [40, 1, 1], .false., .false., lay)
    n = lay%bsize(1)
    g = lay%ng(1)
    allocate(q(1-g:n+g, 1, 1, n_solid), rhs(n, 1, 1, n_solid), bigphi(1-g:n+g, 1, 1))
    sdev = 0.05_wp * [1.0_wp, -0.5_wp, -0.5_wp, 0.2_wp, 0.0_wp, 0.0_wp]
    do i = 1 - g, n + g
      x = lay%lo(1) + (real(i, wp) - 0.5_wp) * lay%dx(1)
      bigphi(i, 1, 1) = -side * (x - lay%lo(1) - 0.5_wp)
      if (bigphi(i, 1, 1) < 0.0_wp) then
        call conserved(n_solid, 1.0_wp, [0.4_wp * side, 0.0_wp, 0.0_wp], 1.0_wp, sdev, &
          0.5_wp, 0.01_wp, qc)
      else
        call conserved(n_solid, 1.0_wp, [0.4_wp * side, 0.0_wp, 0.0_wp], 1.0_wp, sdev, &
          5.0e-7_wp, 2.0e-8_wp, qc)
      end if
      q(i, 1, 1, :) = qc
    end do
    call euler_work_init(lay, n_solid, work)
    call compute_rhs(lay, solid, schemes(is), flux_kind_llf, scalar_flux_upwind, q, rhs, work, &
      bflux, bigphi)
    real_cell = merge(n / 2 + 1, n / 2, side == 1)
    ghost_cell = merge(n / 2, n / 2 + 1, side == 1)
    tag = 'surface 1D ' // trim(scheme_names(is)) // merge(' ghosts left ', ' ghosts right', &
      side == 1) // ': '
    call check_close(tag // 'the real surface cell keeps its eps_p (rhs rho eps_p = 0.5 rhs rho)', &
      rhs(real_cell, 1, 1, i_epsp), 0.5_wp * rhs(real_cell, 1, 1, i_rho), &
      1.0e-14_wp * abs(q(real_cell, 1, 1, i_rho)) / lay%dx(1))
    ! dt at cfl 0.5 of the longitudinal speed (bulk 1.4 p / rho, shear 4 G / 3 rho, G = 1)
    dt = 0.5_wp * lay%dx(1) / (0.4_wp + sqrt(1.4_wp + 4.0_wp / 3.0_wp))
    call check(tag // 'the ghost beside it keeps rho eps_p >= 0 over a step', &
      q(ghost_cell, 1, 1, i_epsp) + dt * rhs(ghost_cell, 1, 1, i_epsp) >= 0.0_wp)
    call check(tag // 'and rho w_c >= 0', &
      q(ghost_cell, 1, 1, i_wcold) + dt * rhs(ghost_cell, 1, 1, i_wcold) >= 0.0_wp)
  end subroutine surface_scalars

  !> A smooth state varying in every direction, halo included (no side conditions needed),
  !> a plane surface across it, and the rates of two boxes, alone and together, against the
  !> whole block's.
  subroutine box_rates(nd, with_strength, axisymmetric)
    integer, intent(in) :: nd
    logical, intent(in) :: with_strength, axisymmetric
    real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
    type(layout_t) :: lay
    type(euler_work_t) :: work
    real(wp), allocatable :: q(:, :, :, :), rhs(:, :, :, :), rbox(:, :, :, :), bigphi(:, :, :)
    real(wp) :: x(3), b, qc(n_solid), sdev(6), bflux(2)
    integer :: i, j, k, nv, t, box(2, 3, 2), lo(3), hi(3), b0, b1
    logical :: inside
    character(len=:), allocatable :: tag
    nv = merge(n_solid, n_euler, with_strength)
    call one_block(nd, [12, 10, 8], .false., axisymmetric, lay)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    allocate(q(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nv), bigphi(lo(1):hi(1), lo(2):hi(2), &
      lo(3):hi(3)))
    allocate(rhs(lay%bsize(1), lay%bsize(2), lay%bsize(3), nv))
    allocate(rbox, mold=rhs)
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          x = lay%lo + ([i, j, k] - 0.5_wp) * lay%dx
          b = sin(2.0_wp * pi * x(1)) * cos(pi * x(2)) + 0.5_wp * sin(3.0_wp * x(3))
          sdev = 0.05_wp * b * [1.0_wp, -0.4_wp, -0.6_wp, 0.3_wp, -0.2_wp, 0.1_wp]
          call conserved(nv, 1.0_wp + 0.2_wp * b, [0.3_wp * b, 0.2_wp - 0.1_wp * b, &
            0.1_wp * b], 1.0_wp + 0.3_wp * b, sdev, 0.2_wp + 0.1_wp * b, 0.01_wp, qc)
          q(i, j, k, :) = qc(1:nv)
          bigphi(i, j, k) = x(1) - lay%lo(1) - 0.37_wp - 0.1_wp * x(2)
        end do
      end do
    end do
    call euler_work_init(lay, nv, work)
    if (with_strength) then
      call compute_rhs(lay, solid, scheme_weno5, flux_kind_llf, scalar_flux_upwind, q, rhs, &
        work, bflux, bigphi)
    else
      call compute_rhs(lay, nostrength, scheme_eno3, flux_kind_hllc, scalar_flux_llf, q, rhs, &
        work, bflux, bigphi)
    end if
    box(:, :, 1) = reshape([3, 7, 2, 5, 3, 6], [2, 3])   ! inside the block
    box(:, :, 2) = reshape([1, 4, 6, 10, 1, 8], [2, 3])   ! at its sides (apart from the first)
    if (nd < 3) box(:, 3, :) = 1
    do t = 1, 3
      ! the first box, the second, both
      b0 = merge(2, 1, t == 2)
      b1 = merge(1, 2, t == 1)
      rbox = huge(1.0_wp)
      if (with_strength) then
        call compute_rhs(lay, solid, scheme_weno5, flux_kind_llf, scalar_flux_upwind, q, &
          rbox, work, bflux, bigphi, box(:, :, b0:b1))
      else
        call compute_rhs(lay, nostrength, scheme_eno3, flux_kind_hllc, scalar_flux_llf, q, &
          rbox, work, bflux, bigphi, box(:, :, b0:b1))
      end if
      tag = 'box ' // achar(48 + t) // ' ' // achar(48 + nd) // 'D ' // &
        trim(merge('axisymmetric ', 'cartesian    ', axisymmetric)) // ' ' // &
        merge('solid', 'gas  ', with_strength) // ': '
      do k = 1, lay%bsize(3)
        do j = 1, lay%bsize(2)
          do i = 1, lay%bsize(1)
            inside = all([i, j, k] >= box(1, :, b0) .and. [i, j, k] <= box(2, :, b0)) .or. &
              all([i, j, k] >= box(1, :, b1) .and. [i, j, k] <= box(2, :, b1))
            if (inside) then
              if (.not. all(abs(rbox(i, j, k, :) - rhs(i, j, k, :)) <= 0.0_wp)) exit
            else
              if (.not. all(abs(rbox(i, j, k, :)) <= 0.0_wp)) exit
            end if
          end do
          if (i <= lay%bsize(1)) exit
        end do
        if (j <= lay%bsize(2)) exit
      end do
      call check(tag // 'the boxes'' rates are the block''s (the same numbers), the others 0', &
        k > lay%bsize(3))
      call check(tag // 'and the boxes'' rates are not all 0', &
        maxval(abs(rbox)) > 1.0e-3_wp)
    end do
  end subroutine box_rates

  real(wp) function cell_pressure(qc) result(p)
    real(wp), intent(in) :: qc(:)
    p = (gas%gamma - 1.0_wp) * (qc(i_en) - 0.5_wp * sum(qc(i_mx:i_mz)**2) / qc(i_rho))
  end function cell_pressure

  !> Halo cells to the periodic images of interior cells.
  subroutine fill_periodic(lay, q)
    type(layout_t), intent(in) :: lay
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    integer :: i, j, k, n(3), s(3)
    n = lay%bsize
    do k = 1 - lay%ng(3), n(3) + lay%ng(3)
      do j = 1 - lay%ng(2), n(2) + lay%ng(2)
        do i = 1 - lay%ng(1), n(1) + lay%ng(1)
          s = modulo([i, j, k] - 1, n) + 1
          if (all(s == [i, j, k])) cycle
          q(i, j, k, :) = q(s(1), s(2), s(3), :)
        end do
      end do
    end do
  end subroutine fill_periodic

  subroutine periodic_update(nd, with_strength, scheme)
    integer, intent(in) :: nd, scheme
    logical, intent(in) :: with_strength
    integer, parameter :: nsteps = 30
    real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
    type(layout_t) :: lay
    type(euler_work_t) :: work
    real(wp), allocatable :: q(:, :, :, :), q0(:, :, :, :), rhs(:, :, :, :)
    real(wp) :: x(3), b, qc(n_solid), sdev(6), before(n_solid), after(n_solid), bflux(2)
    real(wp) :: rate, dt
    integer :: nv, i, j, step, stage, m, n(3)
    logical :: admissible
    character(len=:), allocatable :: tag
    nv = merge(n_solid, n_euler, with_strength)
    call one_block(nd, [48, 32, 1], .true., .false., lay)
    n = lay%bsize
    allocate(q(1-lay%ng(1):n(1)+lay%ng(1), 1-lay%ng(2):n(2)+lay%ng(2), 1:1, nv))
    allocate(q0(n(1), n(2), 1, nv), rhs(n(1), n(2), 1, nv))
    do j = 1, n(2)
      do i = 1, n(1)
        x = lay%lo + ([i, j, 1] - 0.5_wp) * lay%dx
        b = sin(2.0_wp * pi * x(1))
        if (nd == 2) b = b * cos(2.0_wp * pi * x(2))
        sdev = 0.05_wp * b * [1.0_wp, -0.5_wp, -0.5_wp, 0.2_wp, 0.1_wp, -0.1_wp]
        call conserved(nv, 1.0_wp + 0.3_wp * b, [0.5_wp + 0.2_wp * b, -0.3_wp, 0.1_wp * b], &
          1.0_wp + 0.4_wp * b**2, sdev, 0.1_wp + 0.1_wp * b, 0.01_wp, qc)
        q(i, j, 1, :) = qc(1:nv)
      end do
    end do
    call euler_work_init(lay, nv, work)
    before(1:nv) = totals(lay, q)
    do step = 1, nsteps
      call fill_periodic(lay, q)
      call euler_max_rate(lay, gas, merge(solid%g, 0.0_wp, with_strength), q, rate, admissible)
      dt = 0.4_wp / rate
      do stage = 1, 3
        if (stage > 1) call fill_periodic(lay, q)
        if (with_strength) then
          call compute_rhs(lay, solid, scheme, flux_kind_llf, scalar_flux_upwind, q, rhs, &
            work, bflux)
        else
          call compute_rhs(lay, nostrength, scheme, flux_kind_hllc, scalar_flux_llf, q, rhs, &
            work, bflux)
        end if
        call rk_stage_update(lay, stage, 3, dt, q, q0, rhs)
      end do
    end do
    after(1:nv) = totals(lay, q)
    tag = 'periodic ' // achar(48 + nd) // 'D ' // merge('solid ', 'gas   ', with_strength) &
      // trim(scheme_names(findloc(schemes, scheme, dim=1))) // ', 30 RK3 steps: '
    call check(tag // 'admissible throughout', admissible)
    call check(tag // 'the state moved', maxval(abs(q(1:n(1), 1:n(2), 1, i_rho) - q0(:, :, 1, &
      i_rho))) > 1.0e-6_wp)
    do m = i_rho, i_en
      call check_close(tag // 'total ' // trim(var_name(m)), after(m), before(m), &
        tol_total * max(1.0_wp, abs(before(m))))
    end do
  end subroutine periodic_update

  !> Totals of every variable over the interior: the sums times the cell volume.
  function totals(lay, q) result(t)
    type(layout_t), intent(in) :: lay
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp) :: t(size(q, 4))
    integer :: m
    do m = 1, size(q, 4)
      t(m) = sum(q(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3), m)) &
        * product(lay%dx(1:lay%ndim))
    end do
  end function totals

  function var_name(m) result(name)
    integer, intent(in) :: m
    character(len=10) :: name
    character(len=10), parameter :: names(5) = [character(len=10) :: 'mass', 'x momentum', &
      'y momentum', 'z momentum', 'energy']
    name = names(m)
  end function var_name

end program test_euler
