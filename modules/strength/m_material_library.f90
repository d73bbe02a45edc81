!> The built-in material library: named parameter sets that a deck can use by name alone
!> (`base_material = 'air'`, `&body material = 'copper'`) or start from in a &material group
!> and override value by value. It owns only the numbers; what they mean is the business of
!> the equation-of-state (eos/) and strength (strength/) modules. Units are SI, except the
!> viscoplastic vp_chi, in MPa^-n as printed (see m_config). Every entry, its source in
!> ../shared/reference/published-data.md and each value chosen against the printed one are
!> tabulated in manual/materials.md; keep the two in step.
module m_material_library
  use m_kinds, only: wp
  use m_config, only: material_t
  implicit none
  private
  public :: library_lookup, library_names

  ! Water as a stiffened gas, p = (gamma - 1) rho e - gamma p_inf (Saurel & Abgrall
  ! parameters). Its temperature follows the thermodynamically consistent closure
  ! T = (p + p_inf) / ((gamma - 1) rho cv), so cv is chosen such that the reference state
  ! (rho0, p0) sits at T0: cv = (p0 + p_inf) / ((gamma - 1) rho0 T0) = 602.1 J/(kg K).
  ! The physical 4186 J/(kg K) would put water at rest at 42 K in this closure; a stiffened
  ! gas with gamma = 4.4 is a mechanical model of water, not a thermal one.
  real(wp), parameter :: water_gamma = 4.4_wp
  real(wp), parameter :: water_p_inf = 6.0e8_wp
  real(wp), parameter :: water_rho0 = 1000.0_wp
  real(wp), parameter :: water_p0 = 1.0e5_wp
  real(wp), parameter :: water_T0 = 293.15_wp
  real(wp), parameter :: water_cv = (water_p0 + water_p_inf) &
    / ((water_gamma - 1.0_wp) * water_rho0 * water_T0)

  ! Solids start at rest at zero pressure and room temperature (section A: T0 = 298 K).
  real(wp), parameter :: room_T = 298.0_wp
  real(wp), parameter :: tq = 0.9_wp        !< Taylor-Quinney share of plastic work
  ! Section A's 'steel' Mie-Gruneisen row, shared by both steels; cv 477 J/(kg K) is the
  ! handbook value, the printed 134 being tungsten's (the table swaps them).
  real(wp), parameter :: steel_rho0 = 7850.0_wp, steel_c0 = 4570.0_wp, steel_s = 1.49_wp, &
    steel_gruneisen = 1.16_wp, steel_cv = 477.0_wp
  ! HMX of section B (the PBX study): strength
  real(wp), parameter :: hmx_g = 7.2e9_wp, hmx_yield = 370.0e6_wp
  ! HMX of section F (Menikoff, EOSlib): the Hugoniot of the Hayes EOS (K0 13.5 GPa, N 9.3,
  ! Gamma0 rho = 1.1 rho0, cv 1500, T0 298 K) fitted by least squares as Us = c0 + s up over
  ! up 0.1-1.5 km/s, the void-collapse speeds (tools/sabre_py/hmx.py; within 1 % of it)
  real(wp), parameter :: hmx_f_c0 = 2801.0_wp, hmx_f_s = 2.362_wp
  ! Section C gives Young's modulus and Poisson's ratio: G = E / (2 (1 + nu)).
  real(wp), parameter :: hmx_c_g = 14240.0e6_wp / (2.0_wp * (1.0_wp + 0.31_wp))
  real(wp), parameter :: htpb_g = 2.5e6_wp / (2.0_wp * (1.0_wp + 0.45_wp))

  integer, parameter :: n_entries = 14
  type(material_t), parameter :: entries(n_entries) = [ &
    ! Air as an ideal gas: e = cv T, so p0 / ((gamma - 1) rho0 cv) = T0 to 4 digits.
    material_t(name='air', eos='ideal_gas', rho0=1.225_wp, p0=101325.0_wp, gamma=1.4_wp, &
      cv=717.5_wp, T0=288.15_wp), &
    material_t(name='water', eos='stiffened_gas', rho0=water_rho0, p0=water_p0, &
      gamma=water_gamma, p_inf=water_p_inf, cv=water_cv, T0=water_T0), &
    ! Metals (section A): linear Us-up Mie-Gruneisen and Johnson-Cook strength.
    material_t(name='copper', eos='mie_gruneisen', rho0=8930.0_wp, p0=0.0_wp, &
      c0=3940.0_wp, s=1.49_wp, gruneisen=2.0_wp, cv=383.5_wp, T0=room_T, &
      strength_model='johnson_cook', shear_modulus=43.33e9_wp, yield0=0.40e9_wp, &
      jc_b=0.177e9_wp, jc_n=1.0_wp, jc_c=0.025_wp, jc_m=1.09_wp, t_melt=1358.0_wp, &
      eps_rate0=1.0_wp, taylor_quinney=tq), &
    ! cv 134 J/(kg K) is the handbook value; the printed 477 is steel's.
    material_t(name='tungsten', eos='mie_gruneisen', rho0=17600.0_wp, p0=0.0_wp, &
      c0=4030.0_wp, s=1.24_wp, gruneisen=1.43_wp, cv=134.0_wp, T0=room_T, &
      strength_model='johnson_cook', shear_modulus=124.0e9_wp, yield0=1.51e9_wp, &
      jc_b=0.177e9_wp, jc_n=0.12_wp, jc_c=0.016_wp, jc_m=1.0_wp, t_melt=1777.0_wp, &
      eps_rate0=1.0_wp, taylor_quinney=tq), &
    material_t(name='high_hard_steel', eos='mie_gruneisen', rho0=steel_rho0, p0=0.0_wp, &
      c0=steel_c0, s=steel_s, gruneisen=steel_gruneisen, cv=steel_cv, T0=room_T, &
      strength_model='johnson_cook', shear_modulus=77.3e9_wp, yield0=1.50e9_wp, &
      jc_b=0.569e9_wp, jc_n=0.22_wp, jc_c=0.003_wp, jc_m=1.17_wp, t_melt=1723.0_wp, &
      eps_rate0=1.0_wp, taylor_quinney=tq), &
    ! Section A gives only the Johnson-Cook set; the Hugoniot, density and Gamma0 are those
    ! of the elastic-plastic piston of issue 3, cv the handbook 0.9 kJ/(kg K).
    material_t(name='aluminium', eos='mie_gruneisen', rho0=2790.0_wp, p0=0.0_wp, &
      c0=5330.0_wp, s=1.34_wp, gruneisen=2.0_wp, cv=900.0_wp, T0=room_T, &
      strength_model='johnson_cook', shear_modulus=26.0e9_wp, yield0=0.324e9_wp, &
      jc_b=0.114e9_wp, jc_n=0.42_wp, jc_c=0.002_wp, jc_m=1.34_wp, t_melt=925.0_wp, &
      eps_rate0=1.0_wp, taylor_quinney=tq), &
    material_t(name='mild_steel', eos='mie_gruneisen', rho0=steel_rho0, p0=0.0_wp, &
      c0=steel_c0, s=steel_s, gruneisen=steel_gruneisen, cv=steel_cv, T0=room_T, &
      strength_model='johnson_cook', shear_modulus=81.8e9_wp, yield0=0.53e9_wp, &
      jc_b=0.229e9_wp, jc_n=0.302_wp, jc_c=0.027_wp, jc_m=1.0_wp, t_melt=1836.0_wp, &
      eps_rate0=1.0_wp, taylor_quinney=tq), &
    ! HMX as physics has it: Menikoff's set (section F, LANL EOSlib), also named hmx_f.
    material_t(name='hmx', eos='mie_gruneisen', rho0=1900.0_wp, p0=0.0_wp, &
      c0=hmx_f_c0, s=hmx_f_s, gruneisen=1.1_wp, cv=1500.0_wp, T0=room_T, &
      strength_model='perfectly_plastic', shear_modulus=12.0e9_wp, yield0=0.26e9_wp, &
      taylor_quinney=tq), &
    ! HMX, section A exactly as printed (c0 2058 m/s, no strength): the set that reproduces
    ! the dissertation as it reads (materials.md).
    material_t(name='hmx_a', eos='mie_gruneisen', rho0=1900.0_wp, p0=0.0_wp, &
      c0=2058.0_wp, s=2.38_wp, gruneisen=1.1_wp, cv=1000.0_wp, T0=room_T, &
      strength_model='none'), &
    ! HMX, section B (mesoscale PBX under a piston); B prints no cv: section A's.
    material_t(name='hmx_b', eos='mie_gruneisen', rho0=1900.0_wp, p0=0.0_wp, &
      c0=2901.0_wp, s=2.058_wp, gruneisen=1.1_wp, cv=1000.0_wp, T0=room_T, &
      strength_model='perfectly_plastic', shear_modulus=hmx_g, yield0=hmx_yield, &
      taylor_quinney=tq), &
    ! HMX, section C: polynomial Mie-Gruneisen and the visco-plastic power law, which has
    ! no threshold (yield0 = 0).
    material_t(name='hmx_c', eos='polynomial_mie_gruneisen', rho0=1900.0_wp, p0=0.0_wp, &
      bulk_modulus=12.5e9_wp, poly_a=22.0e9_wp, poly_b=15.0e9_wp, gruneisen=1.03_wp, &
      cv=2500.0_wp, T0=room_T, strength_model='viscoplastic_power_law', &
      shear_modulus=hmx_c_g, yield0=0.0_wp, vp_chi=1.08_wp, vp_m=-0.79_wp, vp_n=1.58_wp, &
      taylor_quinney=tq), &
    ! HMX, section F: Menikoff's EOSlib set. Strength Y 0.26 GPa, G 12 GPa, cv 1.5 kJ/(kg K),
    ! Gamma0 1.1; the Hayes EOS (K0 13.5 GPa, N 9.3) as its Hugoniot's linear Us-up fit.
    material_t(name='hmx_f', eos='mie_gruneisen', rho0=1900.0_wp, p0=0.0_wp, &
      c0=hmx_f_c0, s=hmx_f_s, gruneisen=1.1_wp, cv=1500.0_wp, T0=room_T, &
      strength_model='perfectly_plastic', shear_modulus=12.0e9_wp, yield0=0.26e9_wp, &
      taylor_quinney=tq), &
    ! Binder of section B: elastic (hyper-elastic, no yield, in the source) with the
    ! polynomial EOS reduced to p = K mu + gruneisen (1 + mu) rho0 e (A = B = 0); B gives
    ! no Gruneisen coefficient or cv: section C's HTPB values.
    material_t(name='binder', eos='polynomial_mie_gruneisen', rho0=1100.0_wp, p0=0.0_wp, &
      bulk_modulus=3.65e9_wp, poly_a=0.0_wp, poly_b=0.0_wp, gruneisen=0.7_wp, &
      cv=975.0_wp, T0=room_T, strength_model='elastic', shear_modulus=0.27e9_wp), &
    material_t(name='htpb', eos='polynomial_mie_gruneisen', rho0=900.0_wp, p0=0.0_wp, &
      bulk_modulus=2.0e9_wp, poly_a=29.4e9_wp, poly_b=1.96e9_wp, gruneisen=0.7_wp, &
      cv=975.0_wp, T0=room_T, strength_model='viscoplastic_power_law', &
      shear_modulus=htpb_g, yield0=0.0_wp, vp_chi=0.54_wp, vp_m=-0.18_wp, vp_n=1.78_wp, &
      taylor_quinney=tq) ]

contains

  !> The library entry called `name` (exact, case-sensitive match). When there is none,
  !> found is false and mat holds the material_t defaults (every parameter unset).
  subroutine library_lookup(name, mat, found)
    character(len=*), intent(in) :: name
    type(material_t), intent(out) :: mat
    logical, intent(out) :: found
    integer :: k
    found = .false.
    do k = 1, n_entries
      if (trim(entries(k)%name) == trim(name)) then
        mat = entries(k)
        found = .true.
        return
      end if
    end do
  end subroutine library_lookup

  !> The entry names as one comma-separated list, e.g. 'air, water, copper, aluminium'.
  subroutine library_names(list)
    character(len=:), allocatable, intent(out) :: list
    integer :: k
    list = trim(entries(1)%name)
    do k = 2, n_entries
      list = list // ', ' // trim(entries(k)%name)
    end do
  end subroutine library_names

end module m_material_library
