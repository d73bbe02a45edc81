!> The resolved input deck as one derived type (DESIGN section 6): a component per deck
!> variable, with its type and default (the material and body groups in material_t and
!> body_t); what each means, its typical value and how it is read, written and checked come
!> from its one line in the table of m_deck_schema. m_deck fills it and validates it; every
!> other module reads it. Reals that the deck left unset hold `unset`; m_deck resolves them
!> (material library, body defaults), so that after m_deck no field holds `unset` unless
!> the table calls it optional.
module m_config
  use m_kinds, only: wp, name_len, path_len, line_len
  use m_errors, only: fatal
  implicit none
  private
  public :: config_t, material_t, body_t, unset, is_set, material_index, choice_index
  public :: max_materials, max_bodies, max_fields

  real(wp), parameter :: unset = -huge(1.0_wp)
  integer, parameter :: max_materials = 16
  integer, parameter :: max_bodies = 64
  integer, parameter :: max_fields = 32

  type :: material_t
    character(len=name_len) :: name = ''
    character(len=name_len) :: eos = ''
    real(wp) :: rho0 = unset
    real(wp) :: p0 = unset
    real(wp) :: gamma = unset
    real(wp) :: p_inf = unset
    real(wp) :: c0 = unset
    real(wp) :: s = unset
    real(wp) :: gruneisen = unset
    real(wp) :: cv = unset
    real(wp) :: T0 = unset
    real(wp) :: bulk_modulus = unset
    real(wp) :: poly_a = unset
    real(wp) :: poly_b = unset
    character(len=name_len) :: strength_model = ''
    real(wp) :: shear_modulus = unset
    real(wp) :: yield0 = unset
    real(wp) :: hardening_modulus = unset
    real(wp) :: jc_b = unset
    real(wp) :: jc_n = unset
    real(wp) :: jc_c = unset
    real(wp) :: jc_m = unset
    real(wp) :: t_melt = unset
    real(wp) :: eps_rate0 = unset
    real(wp) :: vp_chi = unset
    real(wp) :: vp_m = unset
    real(wp) :: vp_n = unset
    real(wp) :: taylor_quinney = unset
  end type material_t

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
    real(wp) :: rho = unset
    real(wp) :: p = unset
    real(wp) :: T = unset
    real(wp) :: amplitude = 0.0_wp
    real(wp) :: wavevector(3) = 0.0_wp
  end type body_t

  type :: config_t
    character(len=path_len) :: deck_file = ''
    ! &run
    character(len=128) :: title = ''
    real(wp) :: t_end = unset
    integer :: max_steps = huge(1)
    real(wp) :: wall_limit = 0.0_wp
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
    real(wp) :: bc_velocity(3) = 0.0_wp
    real(wp) :: bc_rise_time = 0.0_wp
    character(len=name_len) :: base_material = ''
    ! &numerics
    character(len=name_len) :: scheme = ''
    character(len=name_len) :: flux = ''
    character(len=name_len) :: scalar_flux = ''
    character(len=line_len) :: numerics_note = ''   ! not read: what m_numerics_defaults chose
    character(len=name_len) :: surface_flux = 'material'
    character(len=name_len) :: conserve = 'mass_energy'
    integer :: rk_order = 3
    real(wp) :: cfl = 0.5_wp
    real(wp) :: dt_max = unset
    character(len=name_len) :: gfm_probe = 'auto'
    integer :: reinit_every = 5
    integer :: band = 6
    real(wp) :: contact_kappa = 1.0_wp
    ! &physics
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
    real(wp) :: plot_dt = 0.0_wp
    integer :: plot_every = 0
    integer :: checkpoint_every = 0
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

  !> The position of name in the choice list names (the names a module exports for a deck
  !> variable). A name not on the list is a programming error: the deck refuses it.
  integer function choice_index(names, name, who) result(k)
    character(len=*), intent(in) :: names(:), name, who
    k = findloc(names, adjustl(name), 1)
    if (k == 0) call fatal(who, "unknown name '" // trim(name) // "'")
  end function choice_index
end module m_config
