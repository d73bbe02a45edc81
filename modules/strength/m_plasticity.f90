!> Elastic-plastic update of the deviatoric stress S (manual/theory.md section 5), on
!> arrays of n points with the six components in the order xx, yy, zz, xy, yz, xz.
!> Hypo-elastic predictor rate (5.1, Jaumann): dS/dt = 2 G D' + W S - S W, D = (L + L^T)/2,
!> D' = D - tr(D) I / 3, W = (L - L^T)/2, L_ij = du_i/dx_j (the caller puts u_r / r into
!> L_33 in axisymmetric runs, which gives the hoop component). Von Mises (5.2):
!> J2 = (Sxx^2 + Syy^2 + Szz^2)/2 + Sxy^2 + Syz^2 + Sxz^2, sigma_eq = sqrt(3 J2).
!> Radial return (5.3): the trace of the trial S is removed first (twice, so that what is left
!> is round-off of the deviator even when the trial trace was large), so J1 = tr(S) = 0 to
!> round-off; if sigma_eq > sigma_y(eps_p, 0, T) the plastic increment d solves the
!> consistency condition sigma_eq - 3 G d = sigma_y(eps_p + d, d / dt, T) -- in closed form
!> for perfectly plastic (d = (sigma_eq - Y0) / 3G) and linear hardening
!> (d = (sigma_eq - Y0 - H eps_p) / (3G + H)), else by Newton's method kept inside a
!> shrinking bracket [0, d_hi] (bisection when a step leaves it) to |residual| <= 1e-13
!> sigma_y (or the rounding floor 4 eps sigma_eq) -- and S is scaled by
!> sigma_y(eps_p + d, d / dt, T) / sigma_eq, so it lands on the yield surface to round-off,
!> and on zero at melt. Plastic work per unit volume of the step (5.4):
!> dwp = (sigma_y(eps_p) + sigma_y(eps_p + d)) / 2 d (the midpoint yield, both at the step's
!> rate; exact for linear hardening), >= 0. A point of a material without strength (or with
!> G <= 0) gets S = 0. Not here: the advection of rho S and rho eps_p, the heating (the
!> caller adds taylor_quinney dwp), the yield models themselves (m_yield).
module m_plasticity
  use m_kinds, only: wp
  use m_yield, only: strength_t, yield_stress, yield_stress_slopes, viscoplastic_rate, &
    strength_none, strength_elastic, strength_perfectly_plastic, strength_linear_hardening, &
    strength_viscoplastic
  implicit none
  private
  public :: radial_return, von_mises, jaumann_source

  real(wp), parameter :: newton_rtol = 1.0e-13_wp
  integer, parameter :: newton_max_iter = 200

contains

  !> Equivalent (von Mises) stress sigma_eq = sqrt(3 J2) of n deviatoric stresses.
  pure subroutine von_mises(n, s, seq)
    integer, intent(in) :: n
    real(wp), intent(in) :: s(n, 6)
    real(wp), intent(out) :: seq(n)
    integer :: i
    do i = 1, n
      seq(i) = sqrt(1.5_wp * (s(i, 1)**2 + s(i, 2)**2 + s(i, 3)**2) &
        + 3.0_wp * (s(i, 4)**2 + s(i, 5)**2 + s(i, 6)**2))
    end do
  end subroutine von_mises

  !> dS/dt = 2 G D' + W S - S W for n points from the full velocity gradient
  !> l(:, i, j) = du_i / dx_j; src has the component order of s.
  pure subroutine jaumann_source(st, n, s, l, src)
    type(strength_t), intent(in) :: st
    integer, intent(in) :: n
    real(wp), intent(in) :: s(n, 6), l(n, 3, 3)
    real(wp), intent(out) :: src(n, 6)
    real(wp) :: g2, div3, w12, w23, w13
    integer :: i
    g2 = 2.0_wp * st%g
    if (st%model == strength_none) g2 = 0.0_wp
    do i = 1, n
      div3 = (l(i, 1, 1) + l(i, 2, 2) + l(i, 3, 3)) / 3.0_wp
      w12 = 0.5_wp * (l(i, 1, 2) - l(i, 2, 1))
      w23 = 0.5_wp * (l(i, 2, 3) - l(i, 3, 2))
      w13 = 0.5_wp * (l(i, 1, 3) - l(i, 3, 1))
      src(i, 1) = g2 * (l(i, 1, 1) - div3) + 2.0_wp * (w12 * s(i, 4) + w13 * s(i, 6))
      src(i, 2) = g2 * (l(i, 2, 2) - div3) + 2.0_wp * (w23 * s(i, 5) - w12 * s(i, 4))
      src(i, 3) = g2 * (l(i, 3, 3) - div3) - 2.0_wp * (w13 * s(i, 6) + w23 * s(i, 5))
      src(i, 4) = g2 * 0.5_wp * (l(i, 1, 2) + l(i, 2, 1)) &
        + w12 * (s(i, 2) - s(i, 1)) + w13 * s(i, 5) + w23 * s(i, 6)
      src(i, 5) = g2 * 0.5_wp * (l(i, 2, 3) + l(i, 3, 2)) &
        + w23 * (s(i, 3) - s(i, 2)) - w12 * s(i, 6) - w13 * s(i, 4)
      src(i, 6) = g2 * 0.5_wp * (l(i, 1, 3) + l(i, 3, 1)) &
        + w13 * (s(i, 3) - s(i, 1)) + w12 * s(i, 5) - w23 * s(i, 4)
    end do
  end subroutine jaumann_source

  !> Return the trial stresses s (in place) to the yield surface; eps_p is updated, T is the
  !> temperature (thermal softening, melt), dt > 0 the step, dwp the plastic work per unit
  !> volume of this step (>= 0). t_melt, when given, is each point's melt temperature (a melt
  !> point that rises with compression, m_yield's melt_temperature) in place of st%t_melt.
  pure subroutine radial_return(st, n, s, eps_p, T, dt, dwp, t_melt)
    type(strength_t), intent(in) :: st
    integer, intent(in) :: n
    real(wp), intent(inout) :: s(n, 6)
    real(wp), intent(inout) :: eps_p(n)
    real(wp), intent(in) :: T(n)
    real(wp), intent(in) :: dt
    real(wp), intent(out) :: dwp(n)
    real(wp), intent(in), optional :: t_melt(n)
    type(strength_t) :: sp
    real(wp) :: sig_trial, sig_y, y_start, d, rate
    integer :: i
    dwp = 0.0_wp
    if (st%model == strength_none .or. .not. st%g > 0.0_wp) then
      s = 0.0_wp
      return
    end if
    call deviator_trace_fix(n, s)
    sp = st
    do i = 1, n
      if (present(t_melt)) sp%t_melt = t_melt(i)
      sig_trial = sqrt(1.5_wp * (s(i, 1)**2 + s(i, 2)**2 + s(i, 3)**2) &
        + 3.0_wp * (s(i, 4)**2 + s(i, 5)**2 + s(i, 6)**2))
      if (.not. sig_trial > yield_stress(sp, eps_p(i), 0.0_wp, T(i))) cycle
      call plastic_increment(sp, sig_trial, eps_p(i), T(i), dt, d, sig_y)
      rate = d / dt
      y_start = yield_stress(sp, eps_p(i), rate, T(i))
      s(i, :) = s(i, :) * (sig_y / sig_trial)
      eps_p(i) = eps_p(i) + d
      dwp(i) = 0.5_wp * (y_start + sig_y) * d
    end do
  end subroutine radial_return

  !> Remove the trace of s from its diagonal. A second pass takes off what the rounding of
  !> the first left (of the size of the removed trace times the machine epsilon).
  pure subroutine deviator_trace_fix(n, s)
    integer, intent(in) :: n
    real(wp), intent(inout) :: s(n, 6)
    real(wp) :: third
    integer :: i, pass
    do pass = 1, 2
      do i = 1, n
        third = (s(i, 1) + s(i, 2) + s(i, 3)) / 3.0_wp
        s(i, 1) = s(i, 1) - third
        s(i, 2) = s(i, 2) - third
        s(i, 3) = s(i, 3) - third
      end do
    end do
  end subroutine deviator_trace_fix

  !> The plastic increment d of one point with trial stress sig_trial > sigma_y(eps_p, 0, T),
  !> and the flow stress sig_y = sigma_y(eps_p + d, d / dt, T) it ends on.
  pure subroutine plastic_increment(st, sig_trial, eps_p, T, dt, d, sig_y)
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: sig_trial, eps_p, T, dt
    real(wp), intent(out) :: d, sig_y
    real(wp) :: g3, y_static, d_lo, d_hi, f, slope, dy_deps, rate_sens, d_new
    integer :: it
    g3 = 3.0_wp * st%g
    if (T >= st%t_melt) then
      d = sig_trial / g3
      sig_y = 0.0_wp
      return
    end if
    select case (st%model)
    case (strength_perfectly_plastic)
      d = (sig_trial - st%y0) / g3
      sig_y = st%y0
      return
    case (strength_linear_hardening)
      d = (sig_trial - st%y0 - st%h * eps_p) / (g3 + st%h)
      sig_y = yield_stress(st, eps_p + d, d / dt, T)
      return
    case (strength_elastic)
      ! only reached when melted, handled above; keep the stress
      d = 0.0_wp
      sig_y = sig_trial
      return
    end select
    ! f(d) = sig_trial - 3 G d - sigma_y(eps_p + d, d / dt) decreases: f(0) > 0, and at the
    ! perfectly plastic estimate (sigma_y frozen at its static value) f <= 0.
    y_static = yield_stress(st, eps_p, 0.0_wp, T)
    d_lo = 0.0_wp
    d_hi = (sig_trial - y_static) / g3
    if (st%model == strength_viscoplastic) then
      ! the rate at which the viscous stress alone takes all the overstress: f <= 0 there too
      d_hi = min(d_hi, dt * viscoplastic_rate(st, sig_trial - st%y0))
    end if
    if (.not. d_hi > 0.0_wp) then
      ! the overstress is below the resolution of d: nothing to return
      d = 0.0_wp
      sig_y = sig_trial
      return
    end if
    d = d_hi
    do it = 1, newton_max_iter
      call yield_stress_slopes(st, eps_p + d, d / dt, T, sig_y, dy_deps, rate_sens)
      f = sig_trial - g3 * d - sig_y
      ! below 4 eps sigma_trial f is rounding noise of the cancelling terms (when the
      ! stress relaxes nearly to zero, sigma_y << sigma_trial)
      if (abs(f) <= max(newton_rtol * sig_y, 4.0_wp * epsilon(1.0_wp) * sig_trial)) exit
      if (f > 0.0_wp) then
        d_lo = d
      else
        d_hi = d
      end if
      if (d_hi - d_lo <= 2.0_wp * epsilon(1.0_wp) * d_hi) exit
      slope = g3 + dy_deps + rate_sens / d
      d_new = d + f / slope
      if (.not. (d_new > d_lo .and. d_new < d_hi)) d_new = 0.5_wp * (d_lo + d_hi)
      d = d_new
    end do
    if (it > newton_max_iter) sig_y = yield_stress(st, eps_p + d, d / dt, T)
  end subroutine plastic_increment

end module m_plasticity
