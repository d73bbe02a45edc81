!> The built-in material library: named parameter sets that a deck can use by name alone
!> (`base_material = 'air'`, `&body material = 'copper'`) or start from in a &material group
!> and override value by value. It owns only the numbers; what they mean is the business of
!> the equation-of-state modules (eos/). Units are SI. Strength parameters join the entries
!> when the strength models arrive.
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

  integer, parameter :: n_entries = 4
  type(material_t), parameter :: entries(n_entries) = [ &
    ! Air as an ideal gas: e = cv T, so p0 / ((gamma - 1) rho0 cv) = T0 to 4 digits.
    material_t(name='air', eos='ideal_gas', rho0=1.225_wp, p0=101325.0_wp, gamma=1.4_wp, &
      cv=717.5_wp, T0=288.15_wp), &
    material_t(name='water', eos='stiffened_gas', rho0=water_rho0, p0=water_p0, &
      gamma=water_gamma, p_inf=water_p_inf, cv=water_cv, T0=water_T0), &
    ! Metals on a linear Us-up Hugoniot (Mie-Gruneisen), at rest at zero pressure.
    material_t(name='copper', eos='mie_gruneisen', rho0=8930.0_wp, p0=0.0_wp, &
      c0=3940.0_wp, s=1.49_wp, gruneisen=2.0_wp, cv=383.5_wp, T0=298.0_wp), &
    material_t(name='aluminium', eos='mie_gruneisen', rho0=2790.0_wp, p0=0.0_wp, &
      c0=5330.0_wp, s=1.34_wp, gruneisen=2.0_wp, cv=900.0_wp, T0=298.0_wp) ]

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
