!> Yield models of the solids (manual/theory.md section 5): the flow stress sigma_y as a
!> function of the effective plastic strain eps_p, its rate eps_rate (1/s) and the
!> temperature T. elastic: sigma_y = huge (never yields); perfectly_plastic: Y0;
!> linear_hardening: Y0 + H eps_p; johnson_cook (5.5): (A + B eps_p^n)(1 + C ln(max(eps_rate
!> / eps_rate0, 1)))(1 - theta^m), theta = (T - T_ref)/(T_melt - T_ref) clipped to [0, 1],
!> T_ref = 298 K (the temperature of the fit, not the EOS reference). Viscoplastic power law
!> (5.6; published-data section C: eps_rate_vp = chi eps_rate^m sigma^n, sigma in MPa, chi
!> in MPa^-n): this code takes the rate on the right to be the plastic rate itself, so that
!> eps_rate_vp^(1 - m) = chi sigma^n, and adds an optional static threshold Y0 (overstress
!> form): sigma_y = Y0 + 1 MPa (eps_rate_vp^(1 - m) / chi)^(1/n). Why: with the total rate
!> on the right and m < 0 (every published set) a body at rest holding a residual stress
!> would flow infinitely fast (eps_rate^m -> infinity as eps_rate -> 0), and the kernel
!> would need the total rate as an extra input; with the plastic rate the law is the
!> published one whenever the plastic rate carries the deformation (sustained flow), and
!> sigma_y is continuous and increasing from Y0 at rest when m < 1 and n > 0, so the
!> consistency condition of the radial return has exactly one root. Every model loses its
!> strength at and above T_melt (sigma_y = 0) when T_melt is given. The melt temperature may
!> rise with compression (Kraut-Kennedy form, melt_temperature): T_melt(rho) = T_melt0 (1 +
!> a (1 - rho0 / rho)), a = melt_slope (0: a constant T_melt). The module owns the
!> parameters (strength_t), the pointwise formulas and the deck's rules of a model's values
!> (strength_resolve, strength_rules: m_deck_check hands them its rule); the return mapping
!> lives in m_plasticity, and nothing here allocates, communicates or writes.
module m_yield
  use m_kinds, only: wp, line_len
  use m_config, only: material_t, is_set
  use m_errors, only: rule_i
  use m_text, only: real_text, got_text
  implicit none
  private
  public :: strength_t, strength_from_material, strength_model_from_name, strength_problem
  public :: strength_resolve, strength_rules, strength_thermal
  public :: strength_model_names, strength_model_needs
  public :: yield_stress, yield_stress_slopes, viscoplastic_rate, melt_temperature
  public :: strength_none, strength_elastic, strength_perfectly_plastic
  public :: strength_linear_hardening, strength_johnson_cook, strength_viscoplastic

  integer, parameter :: strength_none = 0
  integer, parameter :: strength_elastic = 1
  integer, parameter :: strength_perfectly_plastic = 2
  integer, parameter :: strength_linear_hardening = 3
  integer, parameter :: strength_johnson_cook = 4
  integer, parameter :: strength_viscoplastic = 5
  !> the deck's names (&material strength_model): name k stands for model k - 1
  character(len=22), parameter :: strength_model_names(6) = [character(len=22) :: 'none', &
    'elastic', 'perfectly_plastic', 'linear_hardening', 'johnson_cook', &
    'viscoplastic_power_law']
  !> the &material values each model needs (m_deck_check asks for them)
  character(len=64), parameter :: strength_model_needs(6) = [character(len=64) :: '', &
    'shear_modulus', 'shear_modulus, yield0', 'shear_modulus, yield0, hardening_modulus', &
    'shear_modulus, yield0, jc_b, jc_n, jc_c, jc_m, t_melt, eps_rate0', &
    'shear_modulus, yield0, vp_chi, vp_m, vp_n']

  real(wp), parameter :: mpa = 1.0e6_wp            !< the power law's stress unit (Pa)
  real(wp), parameter :: exp_max = 700.0_wp        !< exp() argument cap (no overflow)
  real(wp), parameter :: eps_p_floor = 1.0e-100_wp !< keeps eps_p^(n-1) finite in slopes

  !> Strength parameters of one material; SI units (Pa, K, 1/s) except vp_chi (MPa^-n).
  type :: strength_t
    integer :: model = strength_none
    real(wp) :: g = 0.0_wp                  !< shear modulus G
    real(wp) :: y0 = 0.0_wp                 !< initial yield; Johnson-Cook A; power-law Y0
    real(wp) :: h = 0.0_wp                  !< linear hardening modulus H
    real(wp) :: jc_b = 0.0_wp
    real(wp) :: jc_n = 1.0_wp
    real(wp) :: jc_c = 0.0_wp
    real(wp) :: jc_m = 1.0_wp
    real(wp) :: t_ref = 298.0_wp
    real(wp) :: t_melt = huge(1.0_wp)       !< huge: never melts; at rho0 when melt_slope > 0
    real(wp) :: melt_slope = 0.0_wp         !< Kraut-Kennedy a; 0: T_melt constant
    real(wp) :: eps_rate0 = 1.0_wp
    real(wp) :: vp_chi = 0.0_wp
    real(wp) :: vp_m = 0.0_wp
    real(wp) :: vp_n = 1.0_wp
    real(wp) :: taylor_quinney = 0.9_wp
  end type strength_t

contains

  !> The model constant of a deck name; -1 when the name is unknown.
  pure integer function strength_model_from_name(name) result(model)
    character(len=*), intent(in) :: name
    model = findloc(strength_model_names, adjustl(name), 1) - 1
    if (len_trim(name) == 0) model = strength_none
    if (trim(adjustl(name)) == 'viscoplastic') model = strength_viscoplastic
  end function strength_model_from_name

  !> Strength parameters of a material; unset fields take the strength_t defaults (G, Y0,
  !> H, B, C = 0; n, m = 1; T_melt = huge; eps_rate0 = 1/s; power law m = 0, n = 1;
  !> Taylor-Quinney 0.9). An unknown model name gives model = -1 (see strength_problem).
  pure function strength_from_material(mat) result(st)
    type(material_t), intent(in) :: mat
    type(strength_t) :: st
    st%model = strength_model_from_name(mat%strength_model)
    if (is_set(mat%shear_modulus)) st%g = mat%shear_modulus
    if (is_set(mat%yield0)) st%y0 = mat%yield0
    if (is_set(mat%hardening_modulus)) st%h = mat%hardening_modulus
    if (is_set(mat%jc_b)) st%jc_b = mat%jc_b
    if (is_set(mat%jc_n)) st%jc_n = mat%jc_n
    if (is_set(mat%jc_c)) st%jc_c = mat%jc_c
    if (is_set(mat%jc_m)) st%jc_m = mat%jc_m
    if (is_set(mat%t_melt)) st%t_melt = mat%t_melt
    if (is_set(mat%eps_rate0)) st%eps_rate0 = mat%eps_rate0
    if (is_set(mat%melt_slope)) st%melt_slope = mat%melt_slope
    if (is_set(mat%vp_chi)) st%vp_chi = mat%vp_chi
    if (is_set(mat%vp_m)) st%vp_m = mat%vp_m
    if (is_set(mat%vp_n)) st%vp_n = mat%vp_n
    if (is_set(mat%taylor_quinney)) st%taylor_quinney = mat%taylor_quinney
  end function strength_from_material

  !> A material's strength model as the deck gives it (m_deck_check, handing its rule): it
  !> needs the eos of a solid (gas: the eos is a gas's); where the deck leaves them out, a
  !> plastic model heats with taylor_quinney = 0.9, johnson_cook's eps_rate0 is 1/s.
  subroutine strength_resolve(m, gas, in_m, rule)
    type(material_t), intent(inout) :: m
    logical, intent(in) :: gas
    character(len=*), intent(in) :: in_m
    procedure(rule_i) :: rule
    call rule(m%strength_model /= 'none' .and. gas, 'material strength_model', "'" &
      // trim(m%strength_model) // "' needs the eos of a solid (mie_gruneisen or polynomial_" &
      // "mie_gruneisen), not '" // trim(m%eos) // "'" // in_m)
    if (plastic(m) .and. .not. is_set(m%taylor_quinney)) m%taylor_quinney = 0.9_wp
    if (m%strength_model == 'johnson_cook' .and. .not. is_set(m%eps_rate0)) m%eps_rate0 = 1.0_wp
  end subroutine strength_resolve

  !> The deck's rules of a strength model's values that involve another value (after the
  !> values it needs were asked for).
  subroutine strength_rules(m, in_m, rule)
    type(material_t), intent(in) :: m
    character(len=*), intent(in) :: in_m
    procedure(rule_i) :: rule
    ! a perfectly plastic solid without a yield stress is a fluid
    if (is_set(m%yield0)) call rule(m%strength_model == 'perfectly_plastic' .and. .not. &
      m%yield0 > 0.0_wp, 'material yield0', 'must be > 0.0' // in_m // got_text(m%yield0))
    if (is_set(m%T0) .and. is_set(m%t_melt)) call rule(.not. m%t_melt > m%T0, &
      'material t_melt', 'must be > T0 = ' // real_text(m%T0) // in_m // got_text(m%t_melt))
    if (is_set(m%melt_slope)) call rule(.not. is_set(m%t_melt), 'material melt_slope', &
      'needs t_melt, the melt temperature at rho0 (HMX: 550 K)' // in_m)
  end subroutine strength_rules

  !> Whether m's model needs the temperature: it softens with it (johnson_cook) or heats by
  !> plastic work (a plastic model with taylor_quinney > 0).
  elemental logical function strength_thermal(m)
    type(material_t), intent(in) :: m
    strength_thermal = m%strength_model == 'johnson_cook' .or. (plastic(m) .and. &
      m%taylor_quinney > 0.0_wp)
  end function strength_thermal

  !> Whether m's model yields: it does plastic work.
  elemental logical function plastic(m)
    type(material_t), intent(in) :: m
    plastic = strength_model_from_name(m%strength_model) >= strength_perfectly_plastic
  end function plastic

  !> '' when the parameters are usable, else what is wrong, why, and a typical value
  !> (for the deck checker, which names the material).
  pure function strength_problem(st) result(msg)
    type(strength_t), intent(in) :: st
    character(len=line_len) :: msg
    msg = ''
    if (st%model < strength_none .or. st%model > strength_viscoplastic) then
      msg = 'unknown strength_model; use none, elastic, perfectly_plastic, ' // &
        'linear_hardening, johnson_cook or viscoplastic_power_law'
    else if (st%model == strength_none) then
      return
    else if (.not. st%g > 0.0_wp) then
      msg = 'shear_modulus must be > 0 for a solid (copper: 43.33e9 Pa)'
    else if (st%y0 < 0.0_wp .or. st%h < 0.0_wp) then
      msg = 'yield0 and hardening_modulus must be >= 0 (copper: 400e6 and 100e6 Pa)'
    else if (st%model == strength_perfectly_plastic .and. .not. st%y0 > 0.0_wp) then
      msg = 'perfectly_plastic needs yield0 > 0 (aluminium: 0.26e9 Pa)'
    else if (st%model == strength_johnson_cook .and. (st%jc_b < 0.0_wp .or. &
      .not. st%jc_n > 0.0_wp .or. st%jc_c < 0.0_wp .or. .not. st%jc_m > 0.0_wp .or. &
      .not. st%eps_rate0 > 0.0_wp)) then
      msg = 'johnson_cook needs jc_b >= 0, jc_n > 0, jc_c >= 0, jc_m > 0, eps_rate0 > 0 ' // &
        '(copper: 0.177e9, 1.0, 0.025, 1.09, 1.0)'
    else if (.not. st%t_melt > st%t_ref) then
      msg = 't_melt must lie above the reference temperature 298 K (copper: 1358 K)'
    else if (st%model == strength_viscoplastic .and. (.not. st%vp_chi > 0.0_wp .or. &
      .not. st%vp_n > 0.0_wp .or. .not. st%vp_m < 1.0_wp)) then
      msg = 'viscoplastic_power_law needs vp_chi > 0, vp_n > 0 and vp_m < 1 so that the ' // &
        'flow stress grows with the plastic rate (HMX: 1.08, 1.58, -0.79)'
    else if (st%melt_slope < 0.0_wp) then
      msg = 'melt_slope must be >= 0: the melt point rises with compression (HMX: 1.53)'
    else if (st%taylor_quinney < 0.0_wp .or. st%taylor_quinney > 1.0_wp) then
      msg = 'taylor_quinney is a fraction of the plastic work, 0 to 1 (metals: 0.9)'
    end if
  end function strength_problem

  !> Flow stress sigma_y(eps_p, eps_rate, T) in Pa (0 at and above the melt temperature).
  elemental real(wp) function yield_stress(st, eps_p, eps_rate, T) result(y)
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: eps_p, eps_rate, T
    real(wp) :: dy_deps, rate_sens
    call yield_stress_slopes(st, eps_p, eps_rate, T, y, dy_deps, rate_sens)
  end function yield_stress

  !> sigma_y and its slopes: dy_deps = d sigma_y / d eps_p (finite, also at eps_p = 0 with
  !> n < 1) and rate_sens = eps_rate d sigma_y / d eps_rate (the rate sensitivity, finite
  !> at every rate; the return divides it by the strain increment).
  elemental subroutine yield_stress_slopes(st, eps_p, eps_rate, T, y, dy_deps, rate_sens)
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: eps_p, eps_rate, T
    real(wp), intent(out) :: y, dy_deps, rate_sens
    real(wp) :: theta, thermal, strain, rate_factor, ratio, p
    y = 0.0_wp
    dy_deps = 0.0_wp
    rate_sens = 0.0_wp
    if (st%model == strength_none) return
    if (T >= st%t_melt) return
    select case (st%model)
    case (strength_elastic)
      y = huge(1.0_wp)
    case (strength_perfectly_plastic)
      y = st%y0
    case (strength_linear_hardening)
      y = st%y0 + st%h * max(eps_p, 0.0_wp)
      dy_deps = st%h
    case (strength_johnson_cook)
      theta = min(max((T - st%t_ref) / (st%t_melt - st%t_ref), 0.0_wp), 1.0_wp)
      thermal = 1.0_wp
      if (theta > 0.0_wp) thermal = 1.0_wp - theta**st%jc_m
      strain = st%y0
      if (eps_p > 0.0_wp) strain = st%y0 + st%jc_b * eps_p**st%jc_n
      ratio = eps_rate / st%eps_rate0
      rate_factor = 1.0_wp
      if (ratio > 1.0_wp) then
        rate_factor = 1.0_wp + st%jc_c * log(ratio)
        rate_sens = strain * st%jc_c * thermal
      end if
      y = strain * rate_factor * thermal
      dy_deps = st%jc_b * st%jc_n * max(eps_p, eps_p_floor)**(st%jc_n - 1.0_wp) &
        * rate_factor * thermal
    case (strength_viscoplastic)
      y = st%y0
      if (.not. st%vp_chi > 0.0_wp) then
        y = huge(1.0_wp)   ! chi = 0: no viscous flow at any stress (strength_problem says so)
      else if (eps_rate > 0.0_wp) then
        p = (1.0_wp - st%vp_m) / st%vp_n
        y = st%y0 + mpa * exp(min(p * log(eps_rate) - log(st%vp_chi) / st%vp_n, exp_max))
        rate_sens = p * (y - st%y0)
      end if
    end select
  end subroutine yield_stress_slopes

  !> The melt temperature at density rho of a material of reference density rho0 (Kraut-
  !> Kennedy): T_melt (1 + a (1 - rho0 / rho)), rising with compression and falling in
  !> tension, kept at T_melt / 2 or above (a floor for material stretched far).
  elemental real(wp) function melt_temperature(st, rho0, rho) result(tm)
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: rho0, rho
    tm = st%t_melt
    if (st%melt_slope > 0.0_wp .and. st%t_melt < huge(1.0_wp)) &
      tm = st%t_melt * max(1.0_wp + st%melt_slope * (1.0_wp - rho0 / rho), 0.5_wp)
  end function melt_temperature

  !> The power law read forwards: the plastic rate (1/s) at which the viscous part of the
  !> flow stress equals sigma_v (Pa), eps_rate_vp = (chi (sigma_v / 1 MPa)^n)^(1/(1 - m)).
  elemental real(wp) function viscoplastic_rate(st, sigma_v) result(rate)
    type(strength_t), intent(in) :: st
    real(wp), intent(in) :: sigma_v
    rate = 0.0_wp
    if (sigma_v <= 0.0_wp .or. .not. st%vp_chi > 0.0_wp) return
    rate = exp(min((log(st%vp_chi) + st%vp_n * log(sigma_v / mpa)) / (1.0_wp - st%vp_m), &
      exp_max))
  end function viscoplastic_rate

end module m_yield
