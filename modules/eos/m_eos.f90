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
!> The linear Us-up fit is singular at eta = 1 / s; beyond eta_c, where 1 - s eta falls to
!> hugoniot_denominator_min (0.1: p_H = 100 rho0 c0^2 eta_c, some 570 GPa for HMX and 8 TPa
!> for copper, far beyond any fit's range), p_H goes on as its tangent in eta, so that every
!> compression has a finite pressure and a real sound speed (theory.md 2, eq. 2.4a).
!> Polynomial Mie-Gruneisen (eq. 2.6, published-data section C): with mu = rho/rho0 - 1,
!> p = K mu + A mu^2 + B mu^3 + gamma rho e (the A and B terms in compression only; gamma
!> (1 + mu) rho0 e = gamma rho e).
!> Temperature of both Mie-Gruneisen kinds (manual/eos-temperature.md, eqs. 2.7-2.13): the
!> isentrope through (rho0, e = 0, T0) is the reference, T = T_s(rho) + (e - e_s(rho)) / cv,
!> which with a constant cv is the one temperature consistent with the pressure. e_s(rho)
!> has no closed form; eos_prepare integrates it once per material into a table in eos_t and
!> eos_temperature interpolates it (quintic Hermite). Without eos_prepare the table is absent
!> and eos_temperature falls back to the old references (T0 + (e - e_H)/cv, T0 + e/cv), which
!> give no shock heating: every Mie-Gruneisen eos_t must be passed to eos_prepare.
!> The deck's rule of a gas's pressure is here too (gas_p_rule). Not here: strength,
!> reaction, mixtures.
module m_eos
  use m_kinds, only: wp
  use m_config, only: material_t, is_set
  use m_text, only: choice_index, real_text, got_text
  use m_errors, only: rule_i
  implicit none
  private
  public :: eos_t, eos_ideal_gas, eos_stiffened_gas, eos_mie_gruneisen, eos_polynomial
  public :: eos_pressure, eos_energy, eos_sound_speed2, eos_temperature, eos_min_pressure
  public :: eos_prepare, eos_names, eos_needs, eos_from_material, gas_p_rule, is_gas_eos

  integer, parameter :: eos_ideal_gas = 1
  integer, parameter :: eos_stiffened_gas = 2
  integer, parameter :: eos_mie_gruneisen = 3
  integer, parameter :: eos_polynomial = 4
  !> the deck's names (&material eos): name k stands for kind k
  character(len=24), parameter :: eos_names(4) = [character(len=24) :: 'ideal_gas', &
    'stiffened_gas', 'mie_gruneisen', 'polynomial_mie_gruneisen']
  !> the &material values each eos needs (m_deck_check asks for them); a gas's rho0, p0 and
  !> cv are asked for only where the scene uses them
  character(len=60), parameter :: eos_needs(4) = [character(len=60) :: 'gamma', &
    'gamma, p_inf', 'rho0, p0, c0, s, gruneisen, cv, T0', &
    'rho0, p0, gruneisen, cv, T0, bulk_modulus, poly_a, poly_b']

  ! Isentrope table (eq. 2.13): nodes eta_j = j deta, eta = 0 is node 0 so that the kink of
  ! the reference curves at rho = rho0 falls on a node; RK4 takes rk4_substeps steps per
  ! interval. The compressed end stops where the Hugoniot denominator 1 - s eta reaches 0.1.
  real(wp), parameter :: isentrope_deta = 1.0e-3_wp
  real(wp), parameter :: isentrope_eta_min = -0.5_wp
  real(wp), parameter :: isentrope_eta_max = 0.6_wp
  real(wp), parameter :: hugoniot_denominator_min = 0.1_wp
  integer, parameter :: rk4_substeps = 10
  !> the row routines take the Mie-Gruneisen reference curve in pieces of this many cells, so
  !> that its scratch is fixed-size (on the stack): an automatic array sized by the row is a
  !> malloc and a free per call, 4 % of a gas run's time before this
  integer, parameter :: row_chunk = 64

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
    !> Filled by eos_prepare for the Mie-Gruneisen kinds: the isentrope through
    !> (rho0, e = 0, T0) at eta_j = j isentrope_deta, j = lbound..ubound(isentrope, 2), as
    !> (e_s, de_s/deta, d2e_s/deta2) in isentrope(0:2, j).
    real(wp), allocatable :: isentrope(:, :)
  end type eos_t

contains

  !> Whether the deck's eos name is a gas's (ideal or stiffened: no strength; its rho0, p0
  !> and cv asked for only where the scene uses them).
  elemental logical function is_gas_eos(name)
    character(len=*), intent(in) :: name
    is_gas_eos = name == eos_names(eos_ideal_gas) .or. name == eos_names(eos_stiffened_gas)
  end function is_gas_eos

  !> A gas's pressure where it is set (var: a material's p0, a body's p; in: which one): at
  !> least 0 in an ideal gas, above -p_inf in a stiffened gas (p_inf missing: an error already).
  !> A rule of the deck (m_deck_check hands its rule).
  subroutine gas_p_rule(var, p, m, in, rule)
    character(len=*), intent(in) :: var, in
    real(wp), intent(in) :: p
    type(material_t), intent(in) :: m
    procedure(rule_i) :: rule
    if (.not. is_set(p)) return
    call rule(m%eos == eos_names(eos_ideal_gas) .and. p < 0.0_wp, var, &
      'must be >= 0 for a gas' // in // got_text(p))
    if (m%eos == eos_names(eos_stiffened_gas) .and. is_set(m%p_inf)) call rule( &
      .not. p > -m%p_inf, var, 'must be > -p_inf = ' // real_text(-m%p_inf) // in // got_text(p))
  end subroutine gas_p_rule

  !> The equation of state of a material (its eos and the constants it sets; the rest keep
  !> the eos_t defaults).
  function eos_from_material(mat) result(eos)
    type(material_t), intent(in) :: mat
    type(eos_t) :: eos
    eos%kind = choice_index(eos_names, mat%eos, 'eos_from_material')
    if (is_set(mat%gamma)) eos%gamma = mat%gamma
    if (is_set(mat%p_inf)) eos%p_inf = mat%p_inf
    if (is_set(mat%rho0)) eos%rho0 = mat%rho0
    if (is_set(mat%c0)) eos%c0 = mat%c0
    if (is_set(mat%s)) eos%s = mat%s
    if (is_set(mat%gruneisen)) eos%gruneisen = mat%gruneisen
    if (is_set(mat%cv)) eos%cv = mat%cv
    if (is_set(mat%T0)) eos%T0 = mat%T0
    if (is_set(mat%bulk_modulus)) eos%bulk = mat%bulk_modulus
    if (is_set(mat%poly_a)) eos%poly_a = mat%poly_a
    if (is_set(mat%poly_b)) eos%poly_b = mat%poly_b
  end function eos_from_material

  !> Hugoniot pressure and energy (eq. 2.4) of a row of densities and, with dph and deh,
  !> their derivatives d/drho: mu = 1 - rho0 / rho; in compression (mu >= 0)
  !> p_H = K mu / (1 - s mu)^2 up to mu_c = (1 - hugoniot_denominator_min) / s and its
  !> tangent in mu beyond (eq. 2.4a), in tension p_H = K (rho / rho0 - 1). Loops without a branch,
  !> so that they vectorise (as a scalar routine called per cell it was a quarter of a solid's
  !> run): both sides are evaluated, each with its argument held to its own side
  !> (max(mu, 0), min(rho, rho0)) so that the side not taken stays finite; the side taken is
  !> the same arithmetic as before, to the bit.
  pure subroutine hugoniot(eos, n, rho, ph, eh, dph, deh)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n)
    real(wp), intent(out) :: ph(n), eh(n)
    real(wp), intent(out), optional :: dph(n), deh(n)
    real(wp) :: mu, muc, den, k0, dmu, mu_c
    integer :: i
    k0 = eos%rho0 * eos%c0**2
    mu_c = huge(1.0_wp)
    if (eos%s > 0.0_wp) mu_c = (1.0_wp - hugoniot_denominator_min) / eos%s
    ! the compressed and the expanded branch into ph and eh first, the choice after: a division
    ! under a condition is a branch to the compiler, which then does not vectorise the loop.
    ! Beyond mu_c the tangent's term is added; below it that term is k0 (...) * 0, exactly 0
    ! (mu_c is huge without an s: no tangent)
    do i = 1, n
      mu = 1.0_wp - eos%rho0 / rho(i)
      muc = min(max(mu, 0.0_wp), mu_c)
      den = 1.0_wp - eos%s * muc
      ph(i) = k0 * muc / den**2 + k0 * (1.0_wp + eos%s * muc) / den**3 * max(mu - mu_c, 0.0_wp)
      eh(i) = k0 * (min(rho(i), eos%rho0) / eos%rho0 - 1.0_wp)
    end do
    do i = 1, n
      mu = 1.0_wp - eos%rho0 / rho(i)
      ph(i) = merge(ph(i), eh(i), mu >= 0.0_wp)
      eh(i) = 0.5_wp * ph(i) * mu / eos%rho0
    end do
    if (.not. present(dph)) return
    do i = 1, n
      mu = 1.0_wp - eos%rho0 / rho(i)
      muc = min(max(mu, 0.0_wp), mu_c)
      dmu = eos%rho0 / rho(i)**2
      den = 1.0_wp - eos%s * muc
      dph(i) = k0 * (1.0_wp + eos%s * muc) / den**3 * dmu
    end do
    do i = 1, n
      mu = 1.0_wp - eos%rho0 / rho(i)
      dmu = eos%rho0 / rho(i)**2
      dph(i) = merge(dph(i), k0 / eos%rho0, mu >= 0.0_wp)
      deh(i) = 0.5_wp * (dph(i) * mu + ph(i) * dmu) / eos%rho0
    end do
  end subroutine hugoniot

  subroutine eos_pressure(eos, n, rho, e, p)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), e(n)
    real(wp), intent(out) :: p(n)
    real(wp) :: ph(row_chunk), eh(row_chunk)
    integer :: i, i0, m
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
      do i0 = 1, n, row_chunk
        m = min(row_chunk, n - i0 + 1)
        call hugoniot(eos, m, rho(i0:), ph, eh)
        p(i0:i0+m-1) = ph(1:m) + eos%gruneisen * eos%rho0 * (e(i0:i0+m-1) - eh(1:m))
      end do
    end select
  end subroutine eos_pressure

  subroutine eos_energy(eos, n, rho, p, e)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), p(n)
    real(wp), intent(out) :: e(n)
    real(wp) :: ph(row_chunk), eh(row_chunk)
    integer :: i, i0, m
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
      do i0 = 1, n, row_chunk
        m = min(row_chunk, n - i0 + 1)
        call hugoniot(eos, m, rho(i0:), ph, eh)
        e(i0:i0+m-1) = eh(1:m) + (p(i0:i0+m-1) - ph(1:m)) / (eos%gruneisen * eos%rho0)
      end do
    end select
  end subroutine eos_energy

  !> c^2 = dp/drho|_e + (p / rho^2) dp/de|_rho (eq. 2.5); may be <= 0 for a state that
  !> is not admissible, which callers test. With e, also the specific internal energy of each
  !> state, as eos_energy gives it (the Mie-Gruneisen reference curve evaluated once for both).
  subroutine eos_sound_speed2(eos, n, rho, p, c2, e)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), p(n)
    real(wp), intent(out) :: c2(n)
    real(wp), intent(out), optional :: e(n)
    real(wp) :: ph(row_chunk), eh(row_chunk), dph(row_chunk), deh(row_chunk), g
    integer :: i, i0, i1, m
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
      do i0 = 1, n, row_chunk
        m = min(row_chunk, n - i0 + 1)
        i1 = i0 + m - 1
        call hugoniot(eos, m, rho(i0:), ph, eh, dph, deh)
        c2(i0:i1) = dph(1:m) - g * deh(1:m) + p(i0:i1) * g / rho(i0:i1)**2
        if (present(e)) e(i0:i1) = eh(1:m) + (p(i0:i1) - ph(1:m)) / g
      end do
      return
    end select
    if (present(e)) call eos_energy(eos, n, rho, p, e)
  end subroutine eos_sound_speed2

  !> T = T_s(rho) + (e - e_s(rho)) / cv for the Mie-Gruneisen kinds (eq. 2.11), with T_s in
  !> closed form (eqs. 2.10, 2.12) and e_s from the table of eos_prepare (eq. 2.13).
  subroutine eos_temperature(eos, n, rho, e, T)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: rho(n), e(n)
    real(wp), intent(out) :: T(n)
    real(wp) :: ph(row_chunk), eh(row_chunk), eta, es
    integer :: i, jlo, jhi, i0, m
    if (allocated(eos%isentrope)) then
      jlo = lbound(eos%isentrope, 2)
      jhi = ubound(eos%isentrope, 2)
    end if
    select case (eos%kind)
    case (eos_ideal_gas)
      T = e / eos%cv
    case (eos_stiffened_gas)
      T = (e - eos%p_inf / rho) / eos%cv
    case (eos_polynomial)
      if (.not. allocated(eos%isentrope)) then
        T = eos%T0 + e / eos%cv
        return
      end if
      do i = 1, n
        eta = 1.0_wp - eos%rho0 / rho(i)
        es = isentrope_energy(eos%isentrope, jlo, jhi, eta)
        T(i) = eos%T0 * (rho(i) / eos%rho0)**eos%gruneisen + (e(i) - es) / eos%cv
      end do
    case default
      if (.not. allocated(eos%isentrope)) then
        do i0 = 1, n, row_chunk
          m = min(row_chunk, n - i0 + 1)
          call hugoniot(eos, m, rho(i0:), ph, eh)
          T(i0:i0+m-1) = eos%T0 + (e(i0:i0+m-1) - eh(1:m)) / eos%cv
        end do
        return
      end if
      do i = 1, n
        eta = 1.0_wp - eos%rho0 / rho(i)
        es = isentrope_energy(eos%isentrope, jlo, jhi, eta)
        T(i) = eos%T0 * exp(eos%gruneisen * eta) + (e(i) - es) / eos%cv
      end do
    end select
  end subroutine eos_temperature

  !> e_s(eta) from the table: quintic Hermite on the interval holding eta (eq. 2.13), exact
  !> for quintics, so the error is O(deta^6). Outside the table the first-order Taylor
  !> expansion about the end node: continuous with its slope, but no longer an isentrope.
  !> A NaN eta takes the extrapolation branch and gives NaN, never an integer conversion.
  pure real(wp) function isentrope_energy(table, jlo, jhi, eta) result(es)
    integer, intent(in) :: jlo, jhi
    real(wp), intent(in) :: table(0:2, jlo:jhi), eta
    real(wp) :: x, t, dy, d0, d1, s0, s1
    integer :: j
    if (eta > jlo * isentrope_deta .and. eta < jhi * isentrope_deta) then
      x = eta / isentrope_deta
      j = min(max(floor(x), jlo), jhi - 1)
      t = x - j
      dy = table(0, j + 1) - table(0, j)
      d0 = table(1, j) * isentrope_deta
      d1 = table(1, j + 1) * isentrope_deta
      s0 = table(2, j) * isentrope_deta**2
      s1 = table(2, j + 1) * isentrope_deta**2
      es = table(0, j) + t * (d0 + t * (0.5_wp * s0 + t * ( &
        (10.0_wp * dy - 6.0_wp * d0 - 4.0_wp * d1 - 0.5_wp * (3.0_wp * s0 - s1)) + t * ( &
        (-15.0_wp * dy + 8.0_wp * d0 + 7.0_wp * d1 + 0.5_wp * (3.0_wp * s0 - 2.0_wp * s1)) &
        + t * (6.0_wp * dy - 3.0_wp * (d0 + d1) - 0.5_wp * (s0 - s1))))))
    else if (eta >= jhi * isentrope_deta) then
      es = table(0, jhi) + table(1, jhi) * (eta - jhi * isentrope_deta)
    else
      es = table(0, jlo) + table(1, jlo) * (eta - jlo * isentrope_deta)
    end if
  end function isentrope_energy

  !> Tabulates the isentrope through (rho0, e = 0, T0) for the Mie-Gruneisen kinds (eq. 2.9):
  !> de_s/deta = p(rho, e_s) / rho0, rho = rho0 / (1 - eta), integrated by RK4 from eta = 0
  !> both ways with the pressure of the EOS itself. Call once per material after every
  !> field is set, and again if a field changes; other kinds get no table.
  subroutine eos_prepare(eos)
    type(eos_t), intent(inout) :: eos
    real(wp) :: eta_max, h, eta, e, k1, k2, k3, k4
    integer :: jlo, jhi, j, m, step
    if (allocated(eos%isentrope)) deallocate(eos%isentrope)
    if (eos%kind /= eos_mie_gruneisen .and. eos%kind /= eos_polynomial) return
    eta_max = isentrope_eta_max
    if (eos%kind == eos_mie_gruneisen .and. eos%s > 0.0_wp) &
      eta_max = min(eta_max, (1.0_wp - hugoniot_denominator_min) / eos%s)
    jhi = floor(eta_max / isentrope_deta)
    jlo = ceiling(isentrope_eta_min / isentrope_deta)
    allocate(eos%isentrope(0:2, jlo:jhi))
    call store_node(0, 0.0_wp)
    do step = 1, -1, -2
      h = step * isentrope_deta / rk4_substeps
      e = 0.0_wp
      j = 0
      do while (j + step >= jlo .and. j + step <= jhi)
        eta = j * isentrope_deta
        do m = 0, rk4_substeps - 1
          k1 = isentrope_slope(eos, eta + m * h, e)
          k2 = isentrope_slope(eos, eta + (m + 0.5_wp) * h, e + 0.5_wp * h * k1)
          k3 = isentrope_slope(eos, eta + (m + 0.5_wp) * h, e + 0.5_wp * h * k2)
          k4 = isentrope_slope(eos, eta + (m + 1) * h, e + h * k3)
          e = e + h * (k1 + 2.0_wp * (k2 + k3) + k4) / 6.0_wp
        end do
        j = j + step
        call store_node(j, e)
      end do
    end do

  contains

    !> Value and the exact first and second derivatives from the ODE (eq. 2.9) at node jj;
    !> d2e_s/deta2 = (dp/drho|_e drho/deta + dp/de|_rho de_s/deta) / rho0 is continuous at
    !> eta = 0 although the reference curves' second derivatives are not.
    subroutine store_node(jj, ee)
      integer, intent(in) :: jj
      real(wp), intent(in) :: ee
      real(wp) :: rho, p, dpdrho, dpde
      rho = eos%rho0 / (1.0_wp - jj * isentrope_deta)
      call pressure_slopes(eos, rho, ee, p, dpdrho, dpde)
      eos%isentrope(0, jj) = ee
      eos%isentrope(1, jj) = p / eos%rho0
      eos%isentrope(2, jj) = (dpdrho * rho**2 / eos%rho0 + dpde * p / eos%rho0) / eos%rho0
    end subroutine store_node

  end subroutine eos_prepare

  !> de_s/deta = p(rho, e) / rho0 on the isentrope (eq. 2.9), rho = rho0 / (1 - eta).
  pure real(wp) function isentrope_slope(eos, eta, e) result(dedeta)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: eta, e
    real(wp) :: p, dpdrho, dpde
    call pressure_slopes(eos, eos%rho0 / (1.0_wp - eta), e, p, dpdrho, dpde)
    dedeta = p / eos%rho0
  end function isentrope_slope

  !> One point of a Mie-Gruneisen kind: p, dp/drho|_e and dp/de|_rho (table set-up only; the
  !> array routines above keep their own loops).
  pure subroutine pressure_slopes(eos, rho, e, p, dpdrho, dpde)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: rho, e
    real(wp), intent(out) :: p, dpdrho, dpde
    real(wp) :: ph(1), eh(1), dph(1), deh(1)
    if (eos%kind == eos_polynomial) then
      dpde = eos%gruneisen * rho
      p = poly_cold(eos, rho) + dpde * e
      dpdrho = poly_dcold(eos, rho) + eos%gruneisen * e
    else
      call hugoniot(eos, 1, [rho], ph, eh, dph, deh)
      dpde = eos%gruneisen * eos%rho0
      p = ph(1) + dpde * (e - eh(1))
      dpdrho = dph(1) - dpde * deh(1)
    end if
  end subroutine pressure_slopes

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
