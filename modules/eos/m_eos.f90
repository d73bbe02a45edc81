!> Equations of state (manual/theory.md section 2): ideal gas, stiffened gas and
!> Mie-Gruneisen with a linear Us-up Hugoniot reference curve. Each returns, on arrays of
!> n points, the pressure p(rho, e), the specific internal energy e(rho, p), the squared
!> sound speed c^2(rho, p) and the temperature T(rho, e). The kind is dispatched once per
!> call, never per point, so that the loops vectorise.
!>
!> Mie-Gruneisen (eq. 2.3): p = p_H(rho) + Gamma0 rho0 (e - e_H(rho)) with Gamma rho constant.
!> The reference curve is the Hugoniot p_H = rho0 c0^2 eta / (1 - s eta)^2,
!> eta = 1 - rho0/rho, in compression (eta >= 0) and the linear branch rho0 c0^2 (rho/rho0 - 1)
!> in expansion; e_H = p_H eta / (2 rho0) (Rankine-Hugoniot energy from rest at e = 0).
!> Temperature: T = T0 + (e - e_H(rho)) / cv (the Hugoniot as the reference curve).
!> Polynomial Mie-Gruneisen (eq. 2.6, published-data section C): with mu = rho/rho0 - 1,
!> p = K mu + A mu^2 + B mu^3 + gamma rho e (the A and B terms in compression only; gamma
!> (1 + mu) rho0 e = gamma rho e), T = T0 + e / cv.
!> Not here: strength, reaction, mixtures.
module m_eos
  use m_kinds, only: wp
  implicit none
  private
  public :: eos_t, eos_ideal_gas, eos_stiffened_gas, eos_mie_gruneisen, eos_polynomial
  public :: eos_pressure, eos_energy, eos_sound_speed2, eos_temperature, eos_min_pressure

  integer, parameter :: eos_ideal_gas = 1
  integer, parameter :: eos_stiffened_gas = 2
  integer, parameter :: eos_mie_gruneisen = 3
  integer, parameter :: eos_polynomial = 4

  type :: eos_t
    integer :: kind = eos_ideal_gas
    real(wp) :: gamma = 1.4_wp
    real(wp) :: p_inf = 0.0_wp
    real(wp) :: rho0 = 1.0_wp
    real(wp) :: c0 = 0.0_wp
    real(wp) :: s = 0.0_wp
    real(wp) :: gruneisen = 0.0_wp
    real(wp) :: cv = 1.0_wp
    real(wp) :: T0 = 0.0_wp
    real(wp) :: bulk = 0.0_wp       !< polynomial: K
    real(wp) :: poly_a = 0.0_wp     !< polynomial: A
    real(wp) :: poly_b = 0.0_wp     !< polynomial: B
  end type eos_t

contains

  !> Hugoniot pressure and energy and their derivatives d/drho (eq. 2.4).
  elemental subroutine hugoniot(eos, rho, ph, eh, dph, deh)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho
    real(wp), intent(out) :: ph, eh, dph, deh
    real(wp) :: mu, den, k0, dmu
    k0 = eos%rho0 * eos%c0**2
    mu = 1.0_wp - eos%rho0 / rho
    dmu = eos%rho0 / rho**2
    if (mu >= 0.0_wp) then
      den = 1.0_wp - eos%s * mu
      ph = k0 * mu / den**2
      dph = k0 * (1.0_wp + eos%s * mu) / den**3 * dmu
    else
      ph = k0 * (rho / eos%rho0 - 1.0_wp)
      dph = k0 / eos%rho0
    end if
    eh = 0.5_wp * ph * mu / eos%rho0
    deh = 0.5_wp * (dph * mu + ph * dmu) / eos%rho0
  end subroutine hugoniot

  subroutine eos_pressure(eos, n, rho, e, p)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), e(n)
    real(wp), intent(out) :: p(n)
    real(wp) :: ph, eh, dph, deh
    integer :: i
    select case (eos%kind)
    case (eos_ideal_gas)
      p = (eos%gamma - 1.0_wp) * rho * e
    case (eos_stiffened_gas)
      p = (eos%gamma - 1.0_wp) * rho * e - eos%gamma * eos%p_inf
    case (eos_polynomial)
      do i = 1, n
        p(i) = poly_cold(eos, rho(i)) + eos%gruneisen * rho(i) * e(i)
      end do
    case default
      do i = 1, n
        call hugoniot(eos, rho(i), ph, eh, dph, deh)
        p(i) = ph + eos%gruneisen * eos%rho0 * (e(i) - eh)
      end do
    end select
  end subroutine eos_pressure

  subroutine eos_energy(eos, n, rho, p, e)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), p(n)
    real(wp), intent(out) :: e(n)
    real(wp) :: ph, eh, dph, deh
    integer :: i
    select case (eos%kind)
    case (eos_ideal_gas)
      e = p / ((eos%gamma - 1.0_wp) * rho)
    case (eos_stiffened_gas)
      e = (p + eos%gamma * eos%p_inf) / ((eos%gamma - 1.0_wp) * rho)
    case (eos_polynomial)
      do i = 1, n
        e(i) = (p(i) - poly_cold(eos, rho(i))) / (eos%gruneisen * rho(i))
      end do
    case default
      do i = 1, n
        call hugoniot(eos, rho(i), ph, eh, dph, deh)
        e(i) = eh + (p(i) - ph) / (eos%gruneisen * eos%rho0)
      end do
    end select
  end subroutine eos_energy

  !> c^2 = dp/drho|_e + (p / rho^2) dp/de|_rho (eq. 2.5); may be <= 0 for a state that
  !> is not admissible, which callers test.
  subroutine eos_sound_speed2(eos, n, rho, p, c2)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), p(n)
    real(wp), intent(out) :: c2(n)
    real(wp) :: ph, eh, dph, deh, g
    integer :: i
    select case (eos%kind)
    case (eos_ideal_gas)
      c2 = eos%gamma * p / rho
    case (eos_stiffened_gas)
      c2 = eos%gamma * (p + eos%p_inf) / rho
    case (eos_polynomial)
      do i = 1, n
        ! dp/drho|_e = dP_cold/drho + gamma e, with e = (p - P_cold) / (gamma rho)
        c2(i) = poly_dcold(eos, rho(i)) + (p(i) - poly_cold(eos, rho(i))) / rho(i) &
          + eos%gruneisen * p(i) / rho(i)
      end do
    case default
      g = eos%gruneisen * eos%rho0
      do i = 1, n
        call hugoniot(eos, rho(i), ph, eh, dph, deh)
        c2(i) = dph - g * deh + p(i) * g / rho(i)**2
      end do
    end select
  end subroutine eos_sound_speed2

  subroutine eos_temperature(eos, n, rho, e, T)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), e(n)
    real(wp), intent(out) :: T(n)
    real(wp) :: ph, eh, dph, deh
    integer :: i
    select case (eos%kind)
    case (eos_ideal_gas)
      T = e / eos%cv
    case (eos_stiffened_gas)
      T = (e - eos%p_inf / rho) / eos%cv
    case (eos_polynomial)
      T = eos%T0 + e / eos%cv
    case default
      do i = 1, n
        call hugoniot(eos, rho(i), ph, eh, dph, deh)
        T(i) = eos%T0 + (e(i) - eh) / eos%cv
      end do
    end select
  end subroutine eos_temperature

  !> Cold part of the polynomial EOS, P_cold = K mu + A mu^2 + B mu^3 (A, B in compression).
  elemental real(wp) function poly_cold(eos, rho) result(pc)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho
    real(wp) :: mu
    mu = rho / eos%rho0 - 1.0_wp
    pc = eos%bulk * mu
    if (mu > 0.0_wp) pc = pc + mu**2 * (eos%poly_a + eos%poly_b * mu)
  end function poly_cold

  elemental real(wp) function poly_dcold(eos, rho) result(dpc)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho
    real(wp) :: mu
    mu = rho / eos%rho0 - 1.0_wp
    dpc = eos%bulk
    if (mu > 0.0_wp) dpc = dpc + mu * (2.0_wp * eos%poly_a + 3.0_wp * eos%poly_b * mu)
    dpc = dpc / eos%rho0
  end function poly_dcold

  !> The lowest admissible pressure of a gas (a state at or below it has no sound speed);
  !> -huge for Mie-Gruneisen solids, which may carry tension.
  pure real(wp) function eos_min_pressure(eos) result(pmin)
    type(eos_t), intent(in) :: eos
    select case (eos%kind)
    case (eos_ideal_gas)
      pmin = 0.0_wp
    case (eos_stiffened_gas)
      pmin = -eos%p_inf
    case default
      pmin = -huge(1.0_wp)
    end select
  end function eos_min_pressure

end module m_eos
