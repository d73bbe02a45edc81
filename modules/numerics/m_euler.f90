!> Right-hand side of the Euler equations on one block (manual/theory.md eq. 1 and 3):
!> L(U) = -sum_d dF_d/dx_d + S, dimension by dimension. Primitive (rho, u, v, w, p) or
!> characteristic variables are reconstructed on each pencil (m_characteristic), face
!> states that are not admissible (rho <= 0 or c^2 <= 0) fall back to the first-order cell
!> values and are counted, the outer state of a face on a reflecting side is set to the
!> mirror of the inner one, and the face flux (m_flux) is differenced. In axisymmetric
!> geometry (x = r, y = z) the radial fluxes are differenced in r-weighted (conservative)
!> form and the hoop pressure p / r is added to the radial momentum.
!> With reaction (m_reaction) the last variable of a phase is rho lambda, after the Euler or
!> the solid variables: 6 or 14 variables instead of 5 or 13. It is carried by the mass flux
!> with lambda upwinded and bounded (eq. 8.6), like eps_p and w_c.
!> Kernels only: no MPI, no I/O, no allocation in the loops (workspace is allocated once).
module m_euler
  use m_kinds, only: wp
  use m_eos, only: eos_t
  use m_characteristic, only: characteristic_work_t, characteristic_work_init
  use m_flux, only: scalar_flux_upwind
  use m_euler_faces, only: numerics_t, faces_and_fluxes
  use m_reconstruct, only: stencil_reach
  use m_yield, only: strength_t
  use m_elastoplastic, only: primitive_row, stress_rates
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_euler, n_solid, i_sxx, i_syy, i_szz, &
    i_sxy, i_syz, i_sxz, i_epsp, i_wcold
  use m_layout, only: layout_t, cell_volume
  implicit none
  private
  public :: numerics_t, euler_work_t, cut_faces_t, euler_work_init, euler_rhs

  !> The pencil frame of direction d: which state variable is each pencil variable,
  !> (rho, u_n, u_t1, u_t2, p, S_nn, S_nt1, S_nt2, S_t1t1, S_t2t2, S_t1t2, eps_p, w_c).
  integer, parameter :: frame(n_solid, 3) = reshape([ &
    1, 2, 3, 4, 5, i_sxx, i_sxy, i_sxz, i_syy, i_szz, i_syz, i_epsp, i_wcold, &
    1, 3, 2, 4, 5, i_syy, i_sxy, i_syz, i_sxx, i_szz, i_sxz, i_epsp, i_wcold, &
    1, 4, 2, 3, 5, i_szz, i_sxz, i_syz, i_sxx, i_syy, i_sxy, i_epsp, i_wcold], [n_solid, 3])
  !> bundles of pencils: x pencils bundled over j at each k, y pencils over i at each k, z
  !> pencils over i at each j
  integer, parameter :: bundle_dir(3) = [2, 1, 1], outer_dir(3) = [3, 3, 2]

  !> Scratch space for one block and one bundle of pencils, allocated once per run. The
  !> bundle buffers are flat and take the shape (nb, cells along the pencil, 5) of each use.
  type :: euler_work_t
    integer :: nv = 5                              !< variables: 5 (gas) or 12 (with strength)
    real(wp), allocatable :: prim(:, :, :, :)      !< (padded block, nv): rho, u, v, w, p, S, eps_p
    real(wp), allocatable :: pw(:)                 !< primitives of a bundle (nb, 1-g:n+g, 5)
    real(wp), allocatable :: wl(:), wr(:), f(:)    !< face states and fluxes (nb, 0:n, 5)
    !> the scalars' fluxes as the right cell of a face sees them where they differ from f,
    !> the left cell's (a ghost's side of a surface face: ghost_fluxes)
    real(wp), allocatable :: fr(:)
    real(wp), allocatable :: el(:), er(:), cl(:), cr(:)   !< (nb, 0:n)
    real(wp), allocatable :: row(:)
    logical, allocatable :: up(:)                  !< faces with upwind scalars (nb, 0:n)
    integer, allocatable :: surf(:)                !< faces on a surface (nb, 0:n; m_flux)
    logical, allocatable :: low(:)                 !< faces forced to first order (nb, 0:n)
    logical, allocatable :: lowb(:)                !< faces with eps_p, w_c at first order
    type(characteristic_work_t) :: chw             !< workspace of m_characteristic
    !> what the last euler_rhs let in through the domain's sides into the real cells: the
    !> rates of mass and total energy (kg/s, W; 2 pi r weighted in axisymmetry), for the
    !> conservation fix of the ghost-fluid method (m_gfm_conserve)
    real(wp) :: bflux(2) = 0.0_wp
  end type euler_work_t

  !> The cut-cell geometry of one phase on one block (m_levelset_cut, m_gfm_cut): the wet
  !> part of each x, y and z face (ax(0:n1, n2, n3), ...), of each cell (alpha), and the
  !> planar fraction (the axisymmetric hoop source). Given to euler_rhs, the face fluxes are
  !> weighted by the apertures and the sources by the fractions: rhs is then the rate of the
  !> phase's content per cell volume (a free surface exchanges nothing across the cut).
  type :: cut_faces_t
    real(wp), allocatable :: ax(:, :, :), ay(:, :, :), az(:, :, :)
    real(wp), allocatable :: alpha(:, :, :), plane(:, :, :)
    !> the cut cells (0 < alpha < 1) of the block and one cell into its halo: their faces
    !> carry eps_p and w_c at the cells' own values (upwind at first order keeps them >= 0
    !> where a face may let out more than a part of a small cell's mass in a stage)
    logical, allocatable :: partial(:, :, :)
    !> the cells (low, high corner) beyond which every fraction and aperture above is 0 and
    !> no cell partial (m_gfm_cut_geometry, which keeps it); the default: not known
    integer :: box(2, 3) = reshape([-huge(1), huge(1), -huge(1), huge(1), -huge(1), huge(1)], &
      [2, 3])
  end type cut_faces_t

contains

  subroutine euler_work_init(lay, nv, work)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: nv
    type(euler_work_t), intent(out) :: work
    integer :: lo(3), hi(3), nmax, gmax, nbmax
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    nmax = maxval(lay%bsize)
    gmax = maxval(lay%ng)
    nbmax = maxval(lay%bsize)
    work%nv = nv
    allocate(work%prim(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nv))
    allocate(work%pw(nbmax * (nmax + 2 * gmax) * nv))
    allocate(work%wl(nbmax * (nmax + 1) * nv), work%wr(nbmax * (nmax + 1) * nv))
    allocate(work%f(nbmax * (nmax + 1) * nv), work%fr(nbmax * (nmax + 1) * nv))
    allocate(work%el(nbmax * (nmax + 1)), work%er(nbmax * (nmax + 1)))
    allocate(work%cl(nbmax * (nmax + 1)), work%cr(nbmax * (nmax + 1)))
    allocate(work%row(lo(1):hi(1)))
    allocate(work%up(nbmax * (nmax + 1)), work%low(nbmax * (nmax + 1)))
    allocate(work%lowb(nbmax * (nmax + 1)))
    allocate(work%surf(nbmax * (nmax + 1)))
    call characteristic_work_init(nbmax * (nmax + 1), nv, work%chw)
  end subroutine euler_work_init

  !> rhs = L(q) over the interior of one block; nfallback counts faces that fell back to
  !> first order; failed is set (and the rest skipped) when even the cell values next to a
  !> face are not admissible: the stage cannot go on and the caller recomputes the step.
  subroutine euler_rhs(lay, eos, st, num, q, rhs, offset, wall, vwall, work, nfallback, &
      failed, bigphi, trouble, cut, boxes)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    type(strength_t), intent(in) :: st    !< strength (used when q carries the stress)
    type(numerics_t), intent(in) :: num
    integer, intent(in) :: offset(3)
    logical, intent(in) :: wall(2, 3)      !< reflecting sides (m_boundary)
    real(wp), intent(in) :: vwall(2, 3)    !< their normal velocities
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(out) :: rhs(:, :, :, :)
    type(euler_work_t), intent(inout) :: work
    integer, intent(inout) :: nfallback
    logical, intent(inout) :: failed
    !> composite level set (< 0: a cell of the material; m_levelset_bodies), when there are
    !> level sets: which faces join two real cells and which lie on the surface
    real(wp), intent(in), optional :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    !> cells of the interior whose last update was inadmissible (the cell-local fallback,
    !> m_step): every face of theirs is reconstructed at first order
    logical, intent(in), optional :: trouble(:, :, :)
    !> the phase's cut-cell geometry: rhs is the rate of its content (m_gfm_cut)
    type(cut_faces_t), intent(in), optional :: cut
    !> the cells whose rates are wanted, boxes (low, high corner; box ib is boxes(:, :, ib),
    !> disjoint): only their pencils are computed, every other cell's rate is 0 (a phase's
    !> cells far beyond its surface, which hold its rest state after the update:
    !> m_gfm_stage); default the whole block
    integer, intent(in), optional :: boxes(:, :, :)
    integer :: lo(3), hi(3), j, k, d, n, g, i, perm(n_solid + 1), nb, nv, m, c, ns, mb, ib
    integer :: i0, i1   !< the cells of a row whose primitives are made
    integer :: bx(2, 3), r3(3), o1, ob, cl, ch
    logical :: split, pwall(2), inj, ink
    real(wp) :: rdx, r
    ! (the cells a stencil reaches: a halo deeper than that is not read here)
    r3 = min(lay%ng, stencil_reach)
    lo = 1 - r3
    hi = lay%bsize + r3
    nv = size(q, 4)
    ! the Euler or solid variables; one more is rho lambda (reaction)
    ns = merge(n_solid, n_euler, nv >= n_solid)
    ! the first of the bounded scalars (eps_p, w_c, lambda) in pencil order
    mb = min(i_epsp, ns + 1)
    work%bflux = 0.0_wp
    if (.not. present(boxes)) then
      bx(1, :) = 1
      bx(2, :) = lay%bsize
      call box_rates()
      return
    end if
    ! (the boxes' cells have their rates set by the x direction's rates_x, the others 0)
    rhs = 0.0_wp
    do ib = 1, size(boxes, 3)
      bx = boxes(:, :, ib)
      call box_rates()
      if (failed) return
    end do

  contains

    !> The rates of the cells of box bx, from its pencils; the fluxes through the domain's
    !> sides added to work%bflux.
    subroutine box_rates()
      ! the primitives of the cells the pencils of the box read: along each direction the
      ! box's cells and the stencil's reach beyond them, so not the halo's edges and corners
      ! (no stencil reaches them; a plan of faces only does not fill them, m_halo)
      do k = max(lo(3), bx(1, 3) - r3(3)), min(hi(3), bx(2, 3) + r3(3))
        do j = max(lo(2), bx(1, 2) - r3(2)), min(hi(2), bx(2, 2) + r3(2))
          inj = j >= bx(1, 2) .and. j <= bx(2, 2)
          ink = k >= bx(1, 3) .and. k <= bx(2, 3)
          if (.not. (inj .or. ink)) cycle
          if (inj .and. ink) then
            i0 = max(lo(1), bx(1, 1) - r3(1))
            i1 = min(hi(1), bx(2, 1) + r3(1))
          else
            i0 = bx(1, 1)
            i1 = bx(2, 1)
          end if
          call primitive_row(eos, i1 - i0 + 1, q(i0:i1, j, k, i_rho), q(i0:i1, j, k, i_mx), &
            q(i0:i1, j, k, i_my), q(i0:i1, j, k, i_mz), q(i0:i1, j, k, i_en), &
            work%prim(i0:i1, j, k, 1), work%prim(i0:i1, j, k, 2), work%prim(i0:i1, j, k, 3), &
            work%prim(i0:i1, j, k, 4), work%prim(i0:i1, j, k, 5), work%row(i0:i1))
          do m = n_euler + 1, nv
            work%prim(i0:i1, j, k, m) = q(i0:i1, j, k, m) / q(i0:i1, j, k, i_rho)
          end do
        end do
      end do
      ! (the x direction's rates, rates_x, set the box's rhs; the others add)
      do d = 1, lay%ndim
        ! the pencils of the box along d: its cells o1 + 1 .. o1 + n, a wall only at the block's
        ! own ends
        o1 = bx(1, d) - 1
        n = bx(2, d) - o1
        pwall = wall(:, d) .and. [o1 == 0, o1 + n == lay%bsize(d)]
        g = lay%ng(d)
        rdx = 1.0_wp / lay%dx(d)
        ! pencil frame (frame(:, d)); the bundle index contiguous (bundle_dir), one bundle at
        ! each c of outer_dir
        perm = [frame(:, d), 0]
        ob = bx(1, bundle_dir(d)) - 1
        nb = bx(2, bundle_dir(d)) - ob
        cl = bx(1, outer_dir(d))
        ch = bx(2, outer_dir(d))
        ! rho lambda keeps its place, after the Euler or solid variables
        if (nv > ns) perm(nv) = nv
        do c = cl, ch
          if (d == 1) then
            call bundle_x(c, nb, n, g, work%pw)
          else
            call bundle_yz(d, c, nb, n, g, work%pw)
          end if
          ! (the scalars' faces: only where there are scalars, beyond the Euler variables)
          if (nv > n_euler) call upwind_faces(d, c, nb, n, work%up, work%surf)
          if (present(trouble)) then
            call low_faces(d, c, nb, n, work%low)
            call faces(work%low)
          else
            call faces()
          end if
          if (failed) return
          if (present(cut)) call wet_faces(d, c, nb, n, work%f)
          split = .false.
          if (present(bigphi) .and. .not. present(cut) .and. nv >= mb) call ghost_fluxes(nb, n, &
            work%surf, work%wl, work%wr, work%f, work%fr, split)
          if (d == 1) then
            call scatter_x(c, nb, n, work%f, work%fr)
          else
            call scatter_yz(d, c, nb, n, work%f, work%fr)
          end if
        end do
      end do
      if (lay%axisymmetric) then
        ! the hoop stress: the pressure term that the r-weighted divergence leaves (eq. 1.1)
        do k = bx(1, 3), bx(2, 3)
          do j = bx(1, 2), bx(2, 2)
            do i = bx(1, 1), bx(2, 1)
              r = lay%lo(1) + (real(offset(1) + i, wp) - 0.5_wp) * lay%dx(1)
              if (present(cut)) then
                ! a cut cell: the hoop stress over its wet part, of planar area plane dr dz
                rhs(i, j, k, i_mx) = rhs(i, j, k, i_mx) + cut%plane(i, j, k) / r &
                  * work%prim(i, j, k, 5)
                if (ns > n_euler) rhs(i, j, k, i_mx) = rhs(i, j, k, i_mx) &
                  - cut%plane(i, j, k) / r * work%prim(i, j, k, i_szz)
                cycle
              end if
              rhs(i, j, k, i_mx) = rhs(i, j, k, i_mx) + work%prim(i, j, k, 5) / r
              ! with strength the hoop stress is p - S_theta theta (S_zz holds the hoop one)
              if (ns > n_euler) rhs(i, j, k, i_mx) = rhs(i, j, k, i_mx) &
                - work%prim(i, j, k, i_szz) / r
            end do
          end do
        end do
      end if

      if (ns > n_euler) then
        if (present(cut)) then
          call stress_rates(lay, st, offset, bx, work%prim, rhs, cut%alpha)
        else
          call stress_rates(lay, st, offset, bx, work%prim, rhs)
        end if
      end if
    end subroutine box_rates

    !> The face states and fluxes of the bundle d, c (m_euler_faces), the faces low (of the
    !> trouble cells) at first order when given, the faces beside a cut cell with their
    !> scalars at the cells' values.
    subroutine faces(low)
      logical, intent(in), optional, contiguous :: low(:)
      if (present(cut) .and. ns > n_euler) then
        call partial_faces(d, c, nb, n, work%lowb)
        call faces_and_fluxes(eos, st%g, num, nb, n, g, nv, ns, pwall, vwall(:, d), &
          work%up, work%surf, work%pw, work%wl, work%wr, work%el, work%er, work%cl, &
          work%cr, work%f, work%chw, nfallback, failed, low, work%lowb)
      else
        call faces_and_fluxes(eos, st%g, num, nb, n, g, nv, ns, pwall, vwall(:, d), &
          work%up, work%surf, work%pw, work%wl, work%wr, work%el, work%er, work%cl, &
          work%cr, work%f, work%chw, nfallback, failed, low)
      end if
    end subroutine faces

    !> The fluxes of a bundle times the wet part of their faces (the phase's cut geometry).
    subroutine wet_faces(dd, c0, nbb, nn, f)
      integer, intent(in) :: dd, c0, nbb, nn
      real(wp), intent(inout) :: f(nbb, 0:nn, nv)
      integer :: mm, ii
      do mm = 1, nv
        do ii = 0, nn
          select case (dd)
          case (1)
            f(:, ii, mm) = f(:, ii, mm) * cut%ax(ii + o1, ob + 1:ob + nbb, c0)
          case (2)
            f(:, ii, mm) = f(:, ii, mm) * cut%ay(ob + 1:ob + nbb, ii + o1, c0)
          case default
            f(:, ii, mm) = f(:, ii, mm) * cut%az(ob + 1:ob + nbb, c0, ii + o1)
          end select
        end do
      end do
    end subroutine wet_faces

    !> The faces of a bundle whose scalars take the upwind flux (m_flux): all of them with
    !> num%scalar_flux upwind and no level sets, else those between two real cells or two
    !> ghosts of the phase (of a cut-cell phase: two wet cells); and (with level sets) the faces
    !> between a real cell and a ghost, surf = 1 when
    !> the left cell is real, 2 when the right one is. On those the transported variables
    !> (S, eps_p, w_c) move with the mass flux at the real cell's value: the ghost's deviator
    !> is built for the traction (MVI reverses the normal stress) and must not be dissipated
    !> into the surface cell (manual/interfaces.md section 4: that pushed the surface cells
    !> past yield every step, eps_p 38 at the foot of the 0.075 mm Taylor bar).
    subroutine upwind_faces(dd, c0, nbb, nn, up, surf)
      integer, intent(in) :: dd, c0, nbb, nn
      logical, intent(out) :: up(nbb, 0:nn)
      integer, intent(out) :: surf(nbb, 0:nn)
      logical :: rl(nbb, 0:nn), rr(nbb, 0:nn)
      integer :: ii, jj
      up = num%scalar_flux == scalar_flux_upwind
      surf = 0
      if (.not. present(bigphi)) return
      select case (dd)
      case (1)   ! x pencils at k = c0, bundled over j
        do ii = 0, nn
          do jj = 1, nbb
            rl(jj, ii) = bigphi(ii + o1, jj + ob, c0) < 0.0_wp
            rr(jj, ii) = bigphi(ii + o1 + 1, jj + ob, c0) < 0.0_wp
          end do
        end do
      case (2)   ! y pencils at k = c0, bundled over i
        do jj = 0, nn
          rl(:, jj) = bigphi(ob + 1:ob + nbb, jj + o1, c0) < 0.0_wp
          rr(:, jj) = bigphi(ob + 1:ob + nbb, jj + o1 + 1, c0) < 0.0_wp
        end do
      case default   ! z pencils at j = c0, bundled over i
        do jj = 0, nn
          rl(:, jj) = bigphi(ob + 1:ob + nbb, c0, jj + o1) < 0.0_wp
          rr(:, jj) = bigphi(ob + 1:ob + nbb, c0, jj + o1 + 1) < 0.0_wp
        end do
      end select
      ! every face but the surface's: a ghost that turns real must start within range as a
      ! real cell does (theory.md 5.1e); a cut-cell phase's dry cells hold no content
      if (num%scalar_flux == scalar_flux_upwind) up = rl .eqv. rr
      if (num%scalar_flux == scalar_flux_upwind .and. present(cut)) up = rl .and. rr
      if (num%surface_llf) return
      where (rl .and. .not. rr) surf = 1
      where (rr .and. .not. rl) surf = 2
    end subroutine upwind_faces

    !> The ghost's side of the surface faces of a bundle: where mass leaves a ghost for the
    !> real cell beside it, the ghost's bounded scalars (eps_p, w_c, lambda) go with it at
    !> the ghost's own face value, the upwind flux, while the face carries the real cell's
    !> value for the real cell (m_flux). f becomes the flux its left cell sees, fr the one its
    !> right cell sees; split tells whether any face of the bundle has two. A ghost's update
    !> matters only where it turns real in the stage (a fresh cell); this keeps those scalars
    !> within their neighbours' range there as in a real cell (theory.md 5.1e). The real
    !> cells see the fluxes they saw before, to the bit.
    subroutine ghost_fluxes(nbb, nn, surf, wl, wr, f, fr, split)
      integer, intent(in) :: nbb, nn
      integer, intent(in) :: surf(nbb, 0:nn)
      real(wp), intent(in) :: wl(nbb, 0:nn, nv), wr(nbb, 0:nn, nv)
      real(wp), intent(inout) :: f(nbb, 0:nn, nv)
      real(wp), intent(out) :: fr(nbb, 0:nn, nv)
      logical, intent(out) :: split
      integer :: ii, jj
      split = any(surf /= 0)
      if (.not. split) return
      fr(:, :, mb:nv) = f(:, :, mb:nv)
      do ii = 0, nn
        do jj = 1, nbb
          ! the ghost on the left, mass leaving it: it sees the upwind flux, the real cell f
          if (surf(jj, ii) == 2 .and. f(jj, ii, 1) > 0.0_wp) &
            f(jj, ii, mb:nv) = f(jj, ii, 1) * wl(jj, ii, mb:nv)
          ! the ghost on the right, mass leaving it
          if (surf(jj, ii) == 1 .and. f(jj, ii, 1) < 0.0_wp) &
            fr(jj, ii, mb:nv) = f(jj, ii, 1) * wr(jj, ii, mb:nv)
        end do
      end do
    end subroutine ghost_fluxes

    !> The faces of a bundle next to a trouble cell (none without the trouble mask).
    subroutine low_faces(dd, c0, nbb, nn, low)
      integer, intent(in) :: dd, c0, nbb, nn
      logical, intent(out) :: low(nbb, 0:nn)
      integer :: ii
      low = .false.
      if (.not. present(trouble)) return
      select case (dd)
      case (1)
        do ii = 1, nn
          low(:, ii - 1) = low(:, ii - 1) .or. trouble(ii + o1, ob + 1:ob + nbb, c0)
          low(:, ii) = low(:, ii) .or. trouble(ii + o1, ob + 1:ob + nbb, c0)
        end do
      case (2)
        do ii = 1, nn
          low(:, ii - 1) = low(:, ii - 1) .or. trouble(ob + 1:ob + nbb, ii + o1, c0)
          low(:, ii) = low(:, ii) .or. trouble(ob + 1:ob + nbb, ii + o1, c0)
        end do
      case default
        do ii = 1, nn
          low(:, ii - 1) = low(:, ii - 1) .or. trouble(ob + 1:ob + nbb, c0, ii + o1)
          low(:, ii) = low(:, ii) .or. trouble(ob + 1:ob + nbb, c0, ii + o1)
        end do
      end select
    end subroutine low_faces

    !> The faces of a bundle beside a cut cell (cut%partial).
    subroutine partial_faces(dd, c0, nbb, nn, lowb)
      integer, intent(in) :: dd, c0, nbb, nn
      logical, intent(out) :: lowb(nbb, 0:nn)
      integer :: ii
      do ii = 0, nn
        select case (dd)
        case (1)
          lowb(:, ii) = cut%partial(ii + o1, ob + 1:ob + nbb, c0) &
            .or. cut%partial(ii + o1 + 1, ob + 1:ob + nbb, c0)
        case (2)
          lowb(:, ii) = cut%partial(ob + 1:ob + nbb, ii + o1, c0) &
            .or. cut%partial(ob + 1:ob + nbb, ii + o1 + 1, c0)
        case default
          lowb(:, ii) = cut%partial(ob + 1:ob + nbb, c0, ii + o1) &
            .or. cut%partial(ob + 1:ob + nbb, c0, ii + o1 + 1)
        end select
      end do
    end subroutine partial_faces

    subroutine bundle_x(k0, nbb, nn, gg, pw)
      integer, intent(in) :: k0, nbb, nn, gg
      real(wp), intent(out) :: pw(nbb, 1-gg:nn+gg, nv)
      integer :: mm, ii, jj
      do mm = 1, nv
        do ii = 1 - gg, nn + gg
          do jj = 1, nbb
            pw(jj, ii, mm) = work%prim(ii + o1, jj + ob, k0, perm(mm))
          end do
        end do
      end do
    end subroutine bundle_x

    !> rhs of the cells of x pencils at k = k0, bundled over j, from the fluxes of their faces
    !> (the bounded scalars' low faces from fr where the bundle is split: ghost_fluxes).
    !> In axisymmetric geometry the radial fluxes are weighted by the face radius and divided
    !> by the cell radius: (r F)_{i+1/2} - (r F)_{i-1/2} over r_i dr (eq. 1.1), which
    !> conserves mass, axial momentum and energy in the volume 2 pi r dr dz.
    subroutine scatter_x(k0, nbb, nn, f, fr)
      integer, intent(in) :: k0, nbb, nn
      real(wp), intent(in) :: f(nbb, 0:nn, nv), fr(nbb, 0:nn, nv)
      integer :: mm, ii, jj
      real(wp) :: wlo(nn), whi(nn), rc, rf
      do ii = 1, nn
        wlo(ii) = rdx
        whi(ii) = rdx
        if (lay%axisymmetric) then
          rf = lay%lo(1) + real(offset(1) + o1 + ii - 1, wp) * lay%dx(1)
          rc = rf + 0.5_wp * lay%dx(1)
          wlo(ii) = rdx * rf / rc
          whi(ii) = rdx * (rf + lay%dx(1)) / rc
        end if
      end do
      do mm = 1, nv
        if (split .and. mm >= mb) then
          call rates_x(k0, nbb, nn, mm, wlo, whi, f(:, :, mm), fr(:, :, mm))
        else
          call rates_x(k0, nbb, nn, mm, wlo, whi, f(:, :, mm), f(:, :, mm))
        end if
      end do
      do jj = 1, nbb
        if (o1 == 0) then
          if (side(1, 1, 1, jj + ob, k0)) call edge(wlo(1) * f(jj, 0, :), 1)
        end if
        if (o1 + nn == lay%bsize(1)) then
          if (side(1, 2, nn + o1, jj + ob, k0)) call edge(-whi(nn) * f(jj, nn, :), nn + o1)
        end if
      end do
    end subroutine scatter_x

    !> y or z pencils (dd = 2, 3) at k = c0 or j = c0, bundled over i
    subroutine bundle_yz(dd, c0, nbb, nn, gg, pw)
      integer, intent(in) :: dd, c0, nbb, nn, gg
      real(wp), intent(out) :: pw(nbb, 1-gg:nn+gg, nv)
      integer :: mm, jj
      do mm = 1, nv
        do jj = 1 - gg, nn + gg
          if (dd == 2) then
            pw(:, jj, mm) = work%prim(ob + 1:ob + nbb, jj + o1, c0, perm(mm))
          else
            pw(:, jj, mm) = work%prim(ob + 1:ob + nbb, c0, jj + o1, perm(mm))
          end if
        end do
      end do
    end subroutine bundle_yz

    !> as scatter_x, for y or z pencils (dd = 2, 3) at k = c0 or j = c0, bundled over i
    subroutine scatter_yz(dd, c0, nbb, nn, f, fr)
      integer, intent(in) :: dd, c0, nbb, nn
      real(wp), intent(in) :: f(nbb, 0:nn, nv), fr(nbb, 0:nn, nv)
      integer :: mm, ii
      logical :: at_lo, at_hi
      do mm = 1, nv
        if (split .and. mm >= mb) then
          call rates_yz(dd, c0, nbb, nn, mm, f(:, :, mm), fr(:, :, mm))
        else
          call rates_yz(dd, c0, nbb, nn, mm, f(:, :, mm), f(:, :, mm))
        end if
      end do
      do ii = 1, nbb
        at_lo = .false.
        at_hi = .false.
        if (dd == 2) then
          if (o1 == 0) at_lo = side(2, 1, ii + ob, 1, c0)
          if (o1 + nn == lay%bsize(2)) at_hi = side(2, 2, ii + ob, nn + o1, c0)
        else
          if (o1 == 0) at_lo = side(3, 1, ii + ob, c0, 1)
          if (o1 + nn == lay%bsize(3)) at_hi = side(3, 2, ii + ob, c0, nn + o1)
        end if
        if (at_lo) call edge(rdx * f(ii, 0, :), ii + ob)
        if (at_hi) call edge(-rdx * f(ii, nn, :), ii + ob)
      end do
    end subroutine scatter_yz

    !> The rates of variable mm (pencil order) of the cells of x pencils at k = k0, bundled
    !> over j, from the fluxes that their high faces (fh) and low faces (fl) carry for them,
    !> face weights whi, wlo. The x direction comes first: this sets rhs, as 0 - the flux
    !> difference (the sum from zero, to the bit, without a pass that zeroes rhs).
    subroutine rates_x(k0, nbb, nn, mm, wlo, whi, fh, fl)
      integer, intent(in) :: k0, nbb, nn, mm
      real(wp), intent(in) :: wlo(nn), whi(nn), fh(nbb, 0:nn), fl(nbb, 0:nn)
      integer :: ii, jj
      do jj = 1, nbb
        do ii = 1, nn
          rhs(ii + o1, jj + ob, k0, perm(mm)) = 0.0_wp &
            - (whi(ii) * fh(jj, ii) - wlo(ii) * fl(jj, ii - 1))
        end do
      end do
    end subroutine rates_x

    !> as rates_x, for y or z pencils (dd = 2, 3) at k = c0 or j = c0, bundled over i
    subroutine rates_yz(dd, c0, nbb, nn, mm, fh, fl)
      integer, intent(in) :: dd, c0, nbb, nn, mm
      real(wp), intent(in) :: fh(nbb, 0:nn), fl(nbb, 0:nn)
      integer :: jj
      do jj = 1, nn
        if (dd == 2) then
          rhs(ob + 1:ob + nbb, jj + o1, c0, perm(mm)) = rhs(ob + 1:ob + nbb, jj + o1, c0, &
            perm(mm)) - rdx * (fh(:, jj) - fl(:, jj - 1))
        else
          rhs(ob + 1:ob + nbb, c0, jj + o1, perm(mm)) = rhs(ob + 1:ob + nbb, c0, jj + o1, &
            perm(mm)) - rdx * (fh(:, jj) - fl(:, jj - 1))
        end if
      end do
    end subroutine rates_yz

    !> whether cell (i0, j0, k0) lies on the domain's low (lh = 1) or high (2) side in
    !> direction dd (not a periodic one) and is real for the phase
    logical function side(dd, lh, i0, j0, k0) result(yes)
      integer, intent(in) :: dd, lh, i0, j0, k0
      if (lh == 1) then
        yes = offset(dd) == 0
      else
        yes = offset(dd) + lay%bsize(dd) == lay%cells(dd)
      end if
      yes = yes .and. .not. lay%periodic(dd)
      ! a cut phase counts every face (its fluxes are weighted by their wet parts)
      if (.not. yes .or. .not. present(bigphi) .or. present(cut)) return
      yes = bigphi(i0, j0, k0) < 0.0_wp
    end function side

    !> add the rate df (per unit volume, pencil order) of a cell of column i0 to work%bflux
    subroutine edge(df, i0)
      real(wp), intent(in) :: df(:)
      integer, intent(in) :: i0
      real(wp) :: dv
      dv = cell_volume(lay, offset, i0)
      work%bflux(1) = work%bflux(1) + df(1) * dv
      work%bflux(2) = work%bflux(2) + df(5) * dv
    end subroutine edge

  end subroutine euler_rhs

end module m_euler
