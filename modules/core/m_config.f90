!> The resolved input deck as one derived type (DESIGN section 6).
!> m_deck fills it from the namelist file and validates it; every other module reads it.
!> Reals that the deck left unset hold `unset`; m_deck resolves them (material library,
!> body defaults) before the driver sees the configuration, so after m_deck returns no
!> field holds `unset` unless it is documented as optional.
module m_config
  use m_kinds, only: wp, name_len, path_len, line_len
  implicit none
  private
  public :: config_t, material_t, body_t, unset, is_set, material_index
  public :: max_materials, max_bodies, max_fields

  real(wp), parameter :: unset = -huge(1.0_wp)
  integer, parameter :: max_materials = 16
  integer, parameter :: max_bodies = 64
  integer, parameter :: max_fields = 32

  !> One &material group. `eos` is 'ideal_gas' | 'stiffened_gas' | 'mie_gruneisen'.
  type :: material_t
    character(len=name_len) :: name = ''
    character(len=name_len) :: eos = ''
    real(wp) :: rho0 = unset        !< reference density (kg/m3)
    real(wp) :: p0 = unset          !< reference (initial) pressure (Pa)
    real(wp) :: gamma = unset       !< ratio of specific heats (ideal, stiffened gas)
    real(wp) :: p_inf = unset       !< stiffening pressure (Pa)
    real(wp) :: c0 = unset          !< Mie-Gruneisen bulk sound speed (m/s)
    real(wp) :: s = unset           !< Mie-Gruneisen Us-up slope
    real(wp) :: gruneisen = unset   !< Mie-Gruneisen Gamma0
    real(wp) :: cv = unset          !< specific heat at constant volume (J/kg K)
    real(wp) :: T0 = unset          !< reference temperature (K)
    ! polynomial Mie-Gruneisen (eos 'polynomial_mie_gruneisen'):
    ! p = K mu + A mu^2 + B mu^3 + gruneisen (1 + mu) rho0 e, mu = rho / rho0 - 1
    real(wp) :: bulk_modulus = unset   !< K (Pa)
    real(wp) :: poly_a = unset         !< A (Pa)
    real(wp) :: poly_b = unset         !< B (Pa)
    ! strength: strength_model 'none' | 'elastic' | 'perfectly_plastic' | 'linear_hardening' |
    ! 'johnson_cook' | 'viscoplastic_power_law'
    character(len=name_len) :: strength_model = ''
    real(wp) :: shear_modulus = unset      !< G (Pa)
    real(wp) :: yield0 = unset             !< initial yield stress; Johnson-Cook A (Pa)
    real(wp) :: hardening_modulus = unset  !< linear hardening H = d sigma_y / d eps_p (Pa)
    real(wp) :: jc_b = unset               !< Johnson-Cook B (Pa)
    real(wp) :: jc_n = unset               !< Johnson-Cook n
    real(wp) :: jc_c = unset               !< Johnson-Cook C
    real(wp) :: jc_m = unset               !< Johnson-Cook m
    real(wp) :: t_melt = unset             !< melt temperature (K): no strength above it
    real(wp) :: eps_rate0 = unset          !< reference plastic strain rate (1/s)
    real(wp) :: vp_chi = unset             !< power law: rate = chi eps_rate^m sigma^n (MPa^-n)
    real(wp) :: vp_m = unset
    real(wp) :: vp_n = unset
    real(wp) :: taylor_quinney = unset     !< share of plastic work turned into heat (0.9)
  end type material_t

  !> One &body group. material may be a material name, 'void' or 'rigid'.
  !> shape: 'box' (lo, hi) | 'sphere' (center, radius) | 'cylinder' (center, radius,
  !> length, axis) | 'half_space' (center = a point on the plane, axis = outward normal).
  type :: body_t
    character(len=name_len) :: name = ''
    character(len=name_len) :: material = ''
    character(len=name_len) :: shape = ''
    real(wp) :: center(3) = 0.0_wp
    real(wp) :: radius = 0.0_wp
    real(wp) :: length = 0.0_wp
    real(wp) :: axis(3) = [0.0_wp, 0.0_wp, 1.0_wp]
    real(wp) :: lo(3) = 0.0_wp
    real(wp) :: hi(3) = 0.0_wp
    real(wp) :: velocity(3) = 0.0_wp
    real(wp) :: rho = unset         !< unset: the material's rho0
    real(wp) :: p = unset           !< unset: the material's p0
    real(wp) :: T = unset           !< optional; when set (and p unset) p follows from rho, T
    real(wp) :: amplitude = 0.0_wp  !< density perturbation rho (1 + amplitude sin(2 pi k.x))
    real(wp) :: wavevector(3) = 0.0_wp   !< k (waves per unit length) of that perturbation
  end type body_t

  type :: config_t
    character(len=path_len) :: deck_file = ''
    ! &run
    character(len=128) :: title = ''
    real(wp) :: t_end = unset
    integer :: max_steps = huge(1)
    real(wp) :: wall_limit = 0.0_wp          !< seconds; 0 = no limit
    character(len=path_len) :: out_dir = 'out'
    logical :: overwrite = .false.
    character(len=path_len) :: restart = ''
    ! &domain
    integer :: ndim = 0
    character(len=name_len) :: geometry = 'cartesian'
    real(wp) :: lo(3) = 0.0_wp
    real(wp) :: hi(3) = 1.0_wp
    integer :: cells(3) = 1
    integer :: block(3) = 1
    character(len=name_len) :: bc_lo(3) = 'outflow'
    character(len=name_len) :: bc_hi(3) = 'outflow'
    real(wp) :: bc_velocity(3) = 0.0_wp      !< normal velocity component on 'velocity' sides
    real(wp) :: bc_rise_time = 0.0_wp        !< linear ramp of bc_velocity from t = 0
    character(len=name_len) :: base_material = ''
    ! &numerics
    ! scheme, flux and scalar_flux left empty are chosen for the scene once its effects are
    ! resolved (m_numerics_defaults; numerics_note says what and why)
    character(len=name_len) :: scheme = ''
    character(len=name_len) :: flux = ''
    character(len=name_len) :: scalar_flux = ''      !< solids: flux of rho eps_p, rho w_c
    character(len=line_len) :: numerics_note = ''
    !> solids with level sets: S, eps_p, w_c across a surface face ('material' | 'llf')
    character(len=name_len) :: surface_flux = 'material'
    !> solids with level sets: what the conservation fix returns ('mass_energy' | 'mass' |
    !> 'none'; m_gfm_conserve)
    character(len=name_len) :: conserve = 'mass_energy'
    integer :: rk_order = 3
    real(wp) :: cfl = 0.5_wp
    real(wp) :: dt_max = unset               !< optional cap on dt (order studies)
    character(len=name_len) :: gfm_probe = 'auto'
    integer :: reinit_every = 5
    integer :: band = 6
    real(wp) :: contact_kappa = 1.0_wp    !< bodies closer than 2 kappa dx are in contact
    ! &physics (switches for later effects; resolved against the materials)
    logical :: strength = .false.
    logical :: thermal = .false.
    logical :: heat_conduction = .false.
    logical :: reaction = .false.
    ! &material, &body
    integer :: n_materials = 0
    type(material_t) :: materials(max_materials)
    integer :: n_bodies = 0
    type(body_t) :: bodies(max_bodies)
    ! &output
    real(wp) :: plot_dt = 0.0_wp             !< 0 = only the final plot (and plot_every)
    integer :: plot_every = 0                !< 0 = off
    integer :: checkpoint_every = 0          !< steps; 0 = only at wall_limit
    integer :: history_every = 1
    integer :: n_fields = 0
    character(len=name_len) :: fields(max_fields) = ''
  end type config_t
contains

  !> True when a real has been given a value (comparing reals for equality is avoided).
  elemental logical function is_set(x)
    real(wp), intent(in) :: x
    is_set = x > 0.5_wp * unset
  end function is_set
  !> Index of the material called name in cfg%materials, 0 when there is none.
  pure integer function material_index(cfg, name) result(k)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: name
    do k = 1, cfg%n_materials
      if (cfg%materials(k)%name == name) return
    end do
    k = 0
  end function material_index
end module m_config
