!> Unit test of the solid flux of m_flux (manual/theory.md eq. 5.1a, 5.1b) on pseudo-random
!> face states: with either scalar flux a uniform specific scalar is carried exactly by the
!> mass flux (consistency); the upwind scalar flux is F_rho phi of the upwind side, zero
!> across a mirror (wall) face; the choice leaves the mass, momentum, energy and stress fluxes
!> bit-identical, and the choice is per face; on a body's surface face every transported
!> variable moves with the mass flux at the real side's value; and one first-order step of
!> rho phi with the upwind flux keeps phi within the range of its neighbours.
program test_flux
  use m_kinds, only: wp
  use m_state, only: n_solid, i_epsp, i_wcold
  use m_flux, only: flux_llf_solid
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_done
  implicit none
  integer, parameter :: nf = 200, nv = n_solid
  real(wp), parameter :: tol = 1.0e-12_wp
  !> the size of the terms of a mass flux (rho c_L, kg / m^2 s): the rounding of F_rho
  real(wp), parameter :: mass_scale = 1.0e7_wp
  real(wp) :: wl(nf, nv), wr(nf, nv), el(nf), er(nf), cl(nf), cr(nf)
  real(wp) :: fu(nf, nv), fl(nf, nv), fm(nf, nv), phi_up
  logical :: mixed(nf)
  integer :: i, m, side(nf)
  logical, parameter :: llf(nf) = .false., upwind(nf) = .true.
  call comm_init()
  call check_start('test_flux')
  call random_states(wl, wr, el, er, cl, cr)

  ! uniform scalars: both fluxes give phi F_rho
  wr(:, i_epsp:i_wcold) = wl(:, i_epsp:i_wcold)
  call flux_llf_solid(nf, nv, llf, wl, wr, el, er, cl, cr, fl)
  call flux_llf_solid(nf, nv, upwind, wl, wr, el, er, cl, cr, fu)
  do m = i_epsp, i_wcold
    call check('uniform phi, llf', maxval(abs(fl(:, m) - fl(:, 1) * wl(:, m)) &
      / (mass_scale * wl(:, m))) < tol)
    call check('uniform phi, upwind', maxval(abs(fu(:, m) - fu(:, 1) * wl(:, m)) &
      / (mass_scale * wl(:, m))) < tol)
  end do

  ! jumps in the scalars: upwind side by the sign of the mass flux; the rest unchanged
  call random_states(wl, wr, el, er, cl, cr)
  call flux_llf_solid(nf, nv, llf, wl, wr, el, er, cl, cr, fl)
  call flux_llf_solid(nf, nv, upwind, wl, wr, el, er, cl, cr, fu)
  call check('mass, momentum, energy, stress unchanged', &
    maxval(abs(fu(:, 1:i_epsp - 1) - fl(:, 1:i_epsp - 1))) <= 0.0_wp)
  mixed = [(mod(i, 2) == 0, i = 1, nf)]
  call flux_llf_solid(nf, nv, mixed, wl, wr, el, er, cl, cr, fm)
  do m = 1, nv
    call check('per-face choice', maxval(abs(fm(:, m) - merge(fu(:, m), fl(:, m), mixed))) &
      <= 0.0_wp)
  end do
  do i = 1, nf
    do m = i_epsp, i_wcold
      phi_up = merge(wl(i, m), wr(i, m), fu(i, 1) >= 0.0_wp)
      call check('upwind value', abs(fu(i, m) - fu(i, 1) * phi_up) &
        <= tol * abs(fu(i, 1) * phi_up))
    end do
  end do

  ! surface faces (one side real, the other a ghost): every transported variable (S, eps_p,
  ! w_c) is the mass flux times the real side's value, whatever the ghost holds; mass,
  ! momentum and energy fluxes are those of LLF
  call random_states(wl, wr, el, er, cl, cr)
  side = [(mod(i, 3), i = 1, nf)]
  call flux_llf_solid(nf, nv, llf, wl, wr, el, er, cl, cr, fl)
  call flux_llf_solid(nf, nv, upwind, wl, wr, el, er, cl, cr, fu)
  call flux_llf_solid(nf, nv, mixed, wl, wr, el, er, cl, cr, fm, side)
  call check('surface: mass, momentum, energy unchanged', &
    maxval(abs(fm(:, 1:5) - fl(:, 1:5))) <= 0.0_wp)
  do i = 1, nf
    do m = 6, nv
      select case (side(i))
      case (1)
        call check('surface: left real', abs(fm(i, m) - fl(i, 1) * wl(i, m)) &
          <= tol * abs(fl(i, 1) * wl(i, m)))
      case (2)
        call check('surface: right real', abs(fm(i, m) - fl(i, 1) * wr(i, m)) &
          <= tol * abs(fl(i, 1) * wr(i, m)))
      case default
        call check('surface: none', abs(fm(i, m) - merge(fu(i, m), fl(i, m), &
          mixed(i) .and. m >= i_epsp)) <= 0.0_wp)
      end select
    end do
  end do

  ! mirror face (a rigid wall at rest): no mass flux, so no scalar flux
  wl = wr
  wl(:, 2) = -wr(:, 2)
  wl(:, 7:8) = -wr(:, 7:8)
  wl(:, i_epsp:i_wcold) = 2.0_wp * wr(:, i_epsp:i_wcold)
  cl = cr
  el = er
  call flux_llf_solid(nf, nv, upwind, wl, wr, el, er, cl, cr, fu)
  call check('wall: no scalar flux', all(abs(fu(:, i_epsp:i_wcold)) <= tol))

  call check_bounds()

  call check_done()

contains

  !> Copper-like states: rho 8000-10000, |u| < 300 m/s, p -1..5 GPa, S within 0.3 GPa,
  !> eps_p and w_c in [0, 2) and [0, 1e5); c a longitudinal speed near 4.7 km/s; e from p.
  subroutine random_states(wl, wr, el, er, cl, cr)
    real(wp), intent(out) :: wl(nf, nv), wr(nf, nv), el(nf), er(nf), cl(nf), cr(nf)
    real(wp) :: r(nf, nv)
    call random_side(wl, r)
    call random_side(wr, r)
    ! the sound speeds from the right side's draw
    cl = 4700.0_wp + 100.0_wp * r(:, 1)
    cr = 4700.0_wp + 100.0_wp * r(:, 2)
    el = wl(:, 5) / (2.0_wp * wl(:, 1))
    er = wr(:, 5) / (2.0_wp * wr(:, 1))
  end subroutine random_states

  !> One side's states w from a fresh draw r (returned for the sound speeds).
  subroutine random_side(w, r)
    real(wp), intent(out) :: w(nf, nv), r(nf, nv)
    call random_number(r)
    w(:, 1) = 8000.0_wp + 2000.0_wp * r(:, 1)
    w(:, 2:4) = 600.0_wp * (r(:, 2:4) - 0.5_wp)
    w(:, 5) = -1.0e9_wp + 6.0e9_wp * r(:, 5)
    w(:, 6:11) = 0.6e9_wp * (r(:, 6:11) - 0.5_wp)
    w(:, i_epsp) = 2.0_wp * r(:, i_epsp)
    w(:, i_wcold) = 1.0e5_wp * r(:, i_wcold)
  end subroutine random_side

  !> One first-order step (face states = cell values, CFL 0.4 on the longitudinal speed) on
  !> a periodic row with density, velocity and scalar all random: the upwind scalar flux
  !> keeps phi in [min, max] of itself and its two neighbours.
  subroutine check_bounds()
    integer, parameter :: n = nf - 1
    real(wp) :: w(0:n+1, nv), c(0:n+1), e(0:n+1), f(nf, nv), rho1, phi1, lam, lo, hi
    real(wp) :: left(nf, nv), right(nf, nv)
    real(wp) :: r(0:n+1, 3)
    integer :: j
    call random_number(r)
    w = 0.0_wp
    w(:, 1) = 8000.0_wp + 2000.0_wp * r(:, 1)
    w(:, 2) = 600.0_wp * (r(:, 2) - 0.5_wp)
    w(:, 5) = 1.0e9_wp
    w(:, i_epsp) = 2.0_wp * r(:, 3)
    w(:, i_wcold) = 1.0_wp
    w(0, :) = w(n, :)
    w(n + 1, :) = w(1, :)
    c = 4700.0_wp
    e = w(:, 5) / (2.0_wp * w(:, 1))
    ! faces j = 1..nf between cells j - 1 and j
    left = w(0:n, :)
    right = w(1:n+1, :)
    call flux_llf_solid(nf, nv, upwind, left, right, e(0:n), e(1:n+1), c(0:n), &
      c(1:n+1), f)
    lam = 0.4_wp / (4700.0_wp + 300.0_wp)
    do j = 1, n
      rho1 = w(j, 1) - lam * (f(j + 1, 1) - f(j, 1))
      phi1 = (w(j, 1) * w(j, i_epsp) - lam * (f(j + 1, i_epsp) - f(j, i_epsp))) / rho1
      lo = minval(w(j-1:j+1, i_epsp))
      hi = maxval(w(j-1:j+1, i_epsp))
      call check('upwind: phi within its neighbours', phi1 >= lo - tol .and. phi1 <= hi + tol)
      phi1 = (w(j, 1) * w(j, i_wcold) - lam * (f(j + 1, i_wcold) - f(j, i_wcold))) / rho1
      call check('upwind: uniform w_c stays uniform', abs(phi1 - 1.0_wp) <= tol)
    end do
  end subroutine check_bounds

end program test_flux
