!> The resolved input deck as one derived type (DESIGN section 6): a component per deck
!> variable, with its type and default (the material and body groups in material_t and
!> body_t); what each means, its typical value and how it is read, written and checked come
!> from its one line in the table of m_deck_schema. m_deck fills it and validates it; every
!> other module reads it. Reals that the deck left unset hold `unset`; m_deck resolves them
!> (material library, body defaults), so that after m_deck no field holds `unset` unless
!> the table calls it optional.
module m_config
  use m_kinds, only: wp, name_len, path_len, line_len
  implicit none
  private
  public :: config_t, material_t, body_t, unset, is_set, material_index
  public :: max_materials, max_bodies

  real(wp), parameter :: unset = -huge(1.0_wp)
  integer, parameter :: max_materials = 16
  integer, parameter :: max_bodies = 64
  integer, parameter :: max_fields = 32

  !> One &material group (the table of m_deck_schema says what each value is).
  type :: material_t
    character(len=name_len) :: name = '', eos = ''
    real(wp) :: rho0 = unset, p0 = unset, gamma = unset, p_inf = unset, c0 = unset, s = unset
    real(wp) :: gruneisen = unset, cv = unset, T0 = unset
    real(wp) :: bulk_modulus = unset, poly_a = unset, poly_b = unset
    character(len=name_len) :: strength_model = ''
    real(wp) :: shear_modulus = unset, yield0 = unset, hardening_modulus = unset
    real(wp) :: jc_b = unset, jc_n = unset, jc_c = unset, jc_m = unset, t_melt = unset
    real(wp) :: eps_rate0 = unset, vp_chi = unset, vp_m = unset, vp_n = unset
    real(wp) :: taylor_quinney = unset, melt_slope = unset
    real(wp) :: conductivity = unset
    character(len=name_len) :: reaction = ''
    real(wp) :: reaction_q = unset
  end type material_t

  !> One &body group.
  type :: body_t
    character(len=name_len) :: name = '', material = '', shape = ''
    real(wp) :: center(3) = 0.0_wp, radius = 0.0_wp, length = 0.0_wp
    real(wp) :: axis(3) = [0.0_wp, 0.0_wp, 1.0_wp], lo(3) = 0.0_wp, hi(3) = 0.0_wp
    real(wp) :: velocity(3) = 0.0_wp, rho = unset, p = unset, T = unset
    real(wp) :: amplitude = 0.0_wp, wavevector(3) = 0.0_wp
    ! the scene generators (shape 'random_spheres', 'random_field' or 'grains' filling the
    ! box lo..hi; m_scene_generate, m_scene_field)
    integer :: seed = 1, count = 0, colours = 0
    character(len=name_len) :: size_distribution = 'fixed'
    real(wp) :: volume_fraction = 0.0_wp, radius_min = 0.0_wp, radius_max = 0.0_wp
    real(wp) :: radius_sigma = 0.0_wp, gap = 0.0_wp, correlation_length = 0.0_wp
  end type body_t

  type :: config_t
    character(len=path_len) :: deck_file = ''
    ! &run
    character(len=128) :: title = ''
    real(wp) :: t_end = unset
    integer :: max_steps = huge(1)
    real(wp) :: wall_limit = 0.0_wp
    character(len=path_len) :: out_dir = 'out', restart = ''
    logical :: overwrite = .false.
    real(wp) :: rebalance_threshold = 1.1_wp   ! max over mean of the ranks' work; 0: never
    integer :: rebalance_every = 100
    logical :: overlap = .false.   ! halo messages in flight while blocks are computed (m_step)
    ! &domain
    integer :: ndim = 0, cells(3) = 1, block(3) = 0   ! block 0: chosen (m_layout)
    character(len=name_len) :: geometry = 'cartesian', base_material = ''
    real(wp) :: lo(3) = 0.0_wp, hi(3) = 1.0_wp, bc_velocity(3) = 0.0_wp, bc_rise_time = 0.0_wp
    character(len=name_len) :: bc_lo(3) = 'outflow', bc_hi(3) = 'outflow'
    ! &numerics
    character(len=name_len) :: scheme = '', flux = '', scalar_flux = ''
    character(len=line_len) :: numerics_note = ''   ! not read: what m_numerics_defaults chose
    character(len=name_len) :: surface_flux = 'material', conserve = 'auto'
    character(len=name_len) :: variables = 'primitive'
    character(len=name_len) :: gfm_probe = 'auto'
    integer :: rk_order = 3, reinit_every = 5, band = 6
    real(wp) :: cfl = 0.5_wp, dt_max = unset, contact_kappa = 1.0_wp, body_follow = unset
    ! &physics
    logical :: strength = .false., thermal = .false., heat_conduction = .false., reaction = .false.
    ! &material, &body
    integer :: n_materials = 0, n_bodies = 0
    type(material_t) :: materials(max_materials)
    type(body_t) :: bodies(max_bodies)
    ! &output
    real(wp) :: plot_dt = 0.0_wp
    integer :: plot_every = 0, checkpoint_every = 0, history_every = 1, n_fields = 0
    real(wp) :: hot_thresholds(4) = [700.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]   !< K (m_hotspot)
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
    ! (a loop: findloc over the component section would copy it to a temporary)
    do k = 1, cfg%n_materials
      if (cfg%materials(k)%name == name) return
    end do
    k = 0
  end function material_index
end module m_config
