!> Resolving and checking a deck once it is read (DESIGN section 6): material names are
!> resolved against the material library (built-in materials that the base material or a
!> body uses are added to the configuration), block sizes left at 0 are chosen, body density
!> and pressure default to those of the body's material, the output fields to a standard
!> list; a material's strength_model defaults to 'none', its taylor_quinney (0.9) and
!> eps_rate0 (1 /s) to their usual values where its model uses them; the &physics switches
!> strength and thermal, when the deck leaves them out, are on exactly when a material in
!> use needs them (manual/materials.md). Every value is checked against its range or its
!> list of choices, and each violation is recorded as one line naming group, variable and a
!> typical value (m_deck_schema); checks that would only repeat an error already found (the
!> values an unknown eos needs, the cells of an unknown ndim) are left out. It does not
!> read the deck (m_deck) and does not interpret the physics: what a material or a shape
!> means is for eos/, strength/ and scene/.
module m_deck_check
  use m_kinds, only: wp, name_len
  use m_config, only: config_t, material_t, is_set, max_materials, max_fields, material_index
  use m_material_library, only: library_lookup, library_names
  use m_yield, only: strength_problem, strength_from_material
  use m_deck_text, only: int_text, real_text, in_list
  use m_deck_parse, only: deck_group_t
  use m_deck_schema, only: fail, bad, deck_error_count, deck_has_error, deck_error_mark
  use m_numerics_defaults, only: numerics_defaults
  implicit none
  private
  public :: deck_check

  character(len=*), parameter :: geometries = 'cartesian, axisymmetric'
  character(len=*), parameter :: bcs = 'outflow, symmetry, rigid, periodic, velocity'
  character(len=*), parameter :: schemes = 'eno1, eno2, eno3, weno5'
  character(len=*), parameter :: fluxes = 'llf, hllc'
  character(len=*), parameter :: scalar_fluxes = 'llf, upwind'
  character(len=*), parameter :: surface_fluxes = 'material, llf'
  character(len=*), parameter :: conserves = 'mass_energy, mass, none'
  character(len=*), parameter :: probes = 'trilinear, least_squares, auto'
  character(len=*), parameter :: eoses = &
    'ideal_gas, stiffened_gas, mie_gruneisen, polynomial_mie_gruneisen'
  character(len=*), parameter :: gas_eoses = 'ideal_gas, stiffened_gas'
  character(len=*), parameter :: strength_models = 'none, elastic, perfectly_plastic, ' &
    // 'linear_hardening, johnson_cook, viscoplastic_power_law'
  !> the models with plastic flow, hence plastic work for Taylor-Quinney heating
  character(len=*), parameter :: plastic_models = 'perfectly_plastic, linear_hardening, ' &
    // 'johnson_cook, viscoplastic_power_law'
  !> the values that mean something only with a strength_model
  character(len=17), parameter :: strength_values(13) = [character(len=17) :: &
    'shear_modulus', 'yield0', 'hardening_modulus', 'jc_b', 'jc_n', 'jc_c', 'jc_m', &
    't_melt', 'eps_rate0', 'vp_chi', 'vp_m', 'vp_n', 'taylor_quinney']
  real(wp), parameter :: default_taylor_quinney = 0.9_wp
  real(wp), parameter :: default_eps_rate0 = 1.0_wp   !< 1 /s
  character(len=*), parameter :: shapes = 'box, sphere, cylinder, half_space'
  character(len=*), parameter :: field_names = 'rho, u, v, w, p, e, T, c, mach, phase, ' &
    // 'sxx, syy, szz, sxy, syz, sxz, eps_p, seq'
  !> the fields that only a deck with strength carries (deviatoric stress, plastic strain,
  !> von Mises stress)
  character(len=*), parameter :: strength_fields = 'sxx, syy, szz, sxy, syz, sxz, eps_p, seq'
  character(len=4), parameter :: default_fields(7) = &
    [character(len=4) :: 'rho', 'u', 'v', 'w', 'p', 'e', 'T']
  integer, parameter :: min_block = 4   !< cells: the halo is 4 deep

contains

  !> Resolve and check cfg as read from groups; the checks run in a fixed order, so the
  !> errors are always reported in that order.
  subroutine deck_check(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    call check_run(base, groups, n_groups, cfg)
    call check_domain(base, groups, n_groups, cfg)
    call check_numerics(base, cfg)
    call check_output(base, cfg)
    call check_materials(base, cfg)
    call check_gas_needs(base, groups, n_groups, cfg)
    call check_physics(base, groups, n_groups, cfg)
    call check_bodies(base, cfg)
    call numerics_defaults(cfg, cfg%numerics_note)
  end subroutine deck_check

  subroutine check_run(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    if (is_set(cfg%t_end)) then
      if (.not. cfg%t_end > 0.0_wp) call bad(base, 'run', 't_end', 'must be > 0, got ' &
        // real_text(cfg%t_end))
    else if (.not. given(groups, n_groups, 'run', 'max_steps')) then
      call bad(base, 'run', 't_end', 'missing required value (give t_end or max_steps)')
    end if
    if (cfg%max_steps < 0) call bad(base, 'run', 'max_steps', 'must be >= 0, got ' &
      // int_text(cfg%max_steps))
    if (cfg%wall_limit < 0.0_wp) call bad(base, 'run', 'wall_limit', &
      'must be >= 0 (0 = no limit), got ' // real_text(cfg%wall_limit))
    if (len_trim(cfg%out_dir) == 0) call bad(base, 'run', 'out_dir', &
      'missing required value (it is empty)')
  end subroutine check_run

  subroutine check_domain(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    character(len=:), allocatable :: nd_text
    character(len=3) :: dd
    integer :: d, nd
    logical :: lo_periodic, hi_periodic

    nd = cfg%ndim
    if (.not. given(groups, n_groups, 'domain', 'ndim')) &
      call bad(base, 'domain', 'ndim', 'missing required value')
    ! without a &domain group at all, its other required values are the same mistake
    if (.not. any([(groups(d)%name == 'domain', d = 1, n_groups)])) &
      call deck_error_mark('&domain *')
    if (nd < 1 .or. nd > 3) call bad(base, 'domain', 'ndim', 'must be 1, 2 or 3, got ' &
      // int_text(nd))
    ! the directions, cells and blocks mean nothing without a valid ndim
    if (deck_has_error('&domain ndim')) return
    nd_text = 'ndim = ' // int_text(nd)
    call check_choice(base, 'domain', 'geometry', cfg%geometry, geometries)
    if (cfg%geometry == 'axisymmetric') then
      if (nd /= 2) call bad(base, 'domain', 'geometry', &
        "'axisymmetric' needs ndim = 2 (x = r, y = z), got " // nd_text)
      if (cfg%lo(1) < 0.0_wp) call bad(base, 'domain', 'lo(1)', &
        'must be >= 0 in axisymmetric geometry (x is the radius), got ' &
        // real_text(cfg%lo(1)))
    end if

    if (.not. given(groups, n_groups, 'domain', 'cells')) &
      call bad(base, 'domain', 'cells', 'missing required value')
    if (.not. given(groups, n_groups, 'domain', 'hi')) &
      call bad(base, 'domain', 'hi', 'missing required value')
    do d = 1, 3
      write(dd, '(a,i1,a)') '(', d, ')'
      if (d <= nd) then
        if (cfg%cells(d) < min_block) call bad(base, 'domain', 'cells' // dd, &
          'must be >= 4 in a direction d <= ' // nd_text // ' (a block holds at least 4 ' &
          // 'cells: the halo is 4 deep), got ' // int_text(cfg%cells(d)))
      else if (cfg%cells(d) /= 1) then
        call bad(base, 'domain', 'cells' // dd, 'must be 1 in a direction d > ' // nd_text &
          // ', got ' // int_text(cfg%cells(d)))
      end if
      if (.not. cfg%hi(d) > cfg%lo(d)) call bad(base, 'domain', 'hi' // dd, &
        'must be > lo' // dd // ' = ' // real_text(cfg%lo(d)) // ', got ' &
        // real_text(cfg%hi(d)))
    end do

    ! block(d) = 0 (the default) asks for a block size chosen here
    do d = 1, 3
      write(dd, '(a,i1,a)') '(', d, ')'
      if (d > nd) then
        cfg%block(d) = 1
      else if (deck_has_error('&domain cells')) then
        cycle
      else if (cfg%block(d) == 0) then
        cfg%block(d) = default_block(cfg%cells(d), nd)
      else if (cfg%block(d) < min_block) then
        call bad(base, 'domain', 'block' // dd, 'must be >= 4 cells (the halo is 4 ' &
          // 'deep; 0 = chosen for you), got ' // int_text(cfg%block(d)))
      end if
      ! any block size goes: the last block along d takes what is left (m_layout); one
      ! larger than the domain is the domain
      if (d <= nd .and. cfg%cells(d) >= min_block) cfg%block(d) = min(cfg%block(d), &
        cfg%cells(d))
    end do

    do d = 1, 3
      write(dd, '(a,i1,a)') '(', d, ')'
      call check_choice(base, 'domain', 'bc_lo' // dd, cfg%bc_lo(d), bcs)
      call check_choice(base, 'domain', 'bc_hi' // dd, cfg%bc_hi(d), bcs)
      lo_periodic = (cfg%bc_lo(d) == 'periodic')
      hi_periodic = (cfg%bc_hi(d) == 'periodic')
      if (d <= nd .and. (lo_periodic .neqv. hi_periodic)) call bad(base, 'domain', &
        merge('bc_hi', 'bc_lo', lo_periodic) // dd, 'periodic on one side only: bc_lo' &
        // dd // " = '" // trim(cfg%bc_lo(d)) // "' but bc_hi" // dd // " = '" &
        // trim(cfg%bc_hi(d)) // "' (both or neither must be 'periodic')")
    end do
    if (cfg%geometry == 'axisymmetric' .and. .not. cfg%lo(1) > 0.0_wp &
      .and. .not. deck_has_error('&domain lo')) then
      if (cfg%bc_lo(1) /= 'symmetry') call bad(base, 'domain', 'bc_lo(1)', &
        "must be 'symmetry' on the axis r = 0 (lo(1) = 0, axisymmetric), got '" &
        // trim(cfg%bc_lo(1)) // "'")
    end if
    if (cfg%bc_rise_time < 0.0_wp) call bad(base, 'domain', 'bc_rise_time', &
      'must be >= 0, got ' // real_text(cfg%bc_rise_time))
  end subroutine check_domain

  !> Cells per block along a direction of n cells (manual/user-guide.md, Blocks): a target of
  !> 64 cells in 1D, 64^2 in 2D and 32^3 in 3D (the halo adds 12 %, 27 % and 95 %), n itself
  !> when n is no larger; else the largest divisor of n between half the target and the
  !> target, so that all blocks are whole, and the target itself when there is none (the
  !> last block takes the rest). Independent of the rank count, so that a deck resolves to
  !> the same blocks (and the same results) on any number of ranks.
  integer function default_block(n, nd) result(b)
    integer, intent(in) :: n, nd
    integer :: target
    target = merge(32, 64, nd == 3)
    if (n <= target) then
      b = n
      return
    end if
    do b = target, target / 2, -1
      if (mod(n, b) == 0) return
    end do
    b = target
  end function default_block

  subroutine check_numerics(base, cfg)
    character(len=*), intent(in) :: base
    type(config_t), intent(in) :: cfg
    ! an empty choice is left to m_numerics_defaults
    if (len_trim(cfg%scheme) > 0) call check_choice(base, 'numerics', 'scheme', cfg%scheme, &
      schemes)
    if (len_trim(cfg%flux) > 0) call check_choice(base, 'numerics', 'flux', cfg%flux, fluxes)
    if (len_trim(cfg%scalar_flux) > 0) call check_choice(base, 'numerics', 'scalar_flux', &
      cfg%scalar_flux, scalar_fluxes)
    call check_choice(base, 'numerics', 'surface_flux', cfg%surface_flux, surface_fluxes)
    call check_choice(base, 'numerics', 'conserve', cfg%conserve, conserves)
    if (cfg%rk_order < 1 .or. cfg%rk_order > 3) call bad(base, 'numerics', 'rk_order', &
      'must be 1, 2 or 3, got ' // int_text(cfg%rk_order))
    if (.not. (cfg%cfl > 0.0_wp .and. cfg%cfl <= 1.0_wp)) call bad(base, 'numerics', 'cfl', &
      'must be in (0, 1], got ' // real_text(cfg%cfl))
    if (is_set(cfg%dt_max)) then
      if (.not. cfg%dt_max > 0.0_wp) call bad(base, 'numerics', 'dt_max', &
        'must be > 0 (leave it out for no cap), got ' // real_text(cfg%dt_max))
    end if
    call check_choice(base, 'numerics', 'gfm_probe', cfg%gfm_probe, probes)
    if (cfg%reinit_every < 1) call bad(base, 'numerics', 'reinit_every', &
      'must be >= 1 (steps between level-set reinitialisations), got ' &
      // int_text(cfg%reinit_every))
    if (cfg%band < min_block) call bad(base, 'numerics', 'band', 'must be >= 4 cells ' &
      // '(the ghost band is 4 deep), got ' // int_text(cfg%band))
    if (.not. (cfg%contact_kappa > 0.0_wp .and. cfg%contact_kappa <= 3.0_wp)) &
      call bad(base, 'numerics', 'contact_kappa', 'must be in (0, 3] (bodies closer than ' &
      // '2 kappa dx are in contact), got ' // real_text(cfg%contact_kappa))
  end subroutine check_numerics

  subroutine check_output(base, cfg)
    character(len=*), intent(in) :: base
    type(config_t), intent(inout) :: cfg
    character(len=name_len) :: kept(max_fields)
    integer :: k, j, n
    if (cfg%plot_dt < 0.0_wp) call bad(base, 'output', 'plot_dt', &
      'must be >= 0 (0 = no plots by time), got ' // real_text(cfg%plot_dt))
    if (cfg%plot_every < 0) call bad(base, 'output', 'plot_every', &
      'must be >= 0 (0 = no plots by step), got ' // int_text(cfg%plot_every))
    if (cfg%checkpoint_every < 0) call bad(base, 'output', 'checkpoint_every', &
      'must be >= 0 (0 = only at wall_limit), got ' // int_text(cfg%checkpoint_every))
    if (cfg%history_every < 1) call bad(base, 'output', 'history_every', &
      'must be >= 1, got ' // int_text(cfg%history_every))
    n = 0
    kept = ''
    do k = 1, max_fields
      if (len_trim(cfg%fields(k)) == 0) cycle
      if (.not. in_list(cfg%fields(k), field_names)) call bad(base, 'output', 'fields', &
        "unknown field '" // trim(cfg%fields(k)) // "' (allowed: " // field_names // ')')
      do j = 1, n
        if (kept(j) == cfg%fields(k)) call bad(base, 'output', 'fields', "field '" &
          // trim(cfg%fields(k)) // "' is listed twice")
      end do
      n = n + 1
      kept(n) = cfg%fields(k)
    end do
    if (n == 0) then
      n = size(default_fields)
      kept(1:n) = default_fields
    end if
    cfg%n_fields = n
    cfg%fields = kept
  end subroutine check_output

  !> Check every &material, then add the library entries that the base material and the
  !> bodies use without defining them.
  subroutine check_materials(base, cfg)
    character(len=*), intent(in) :: base
    type(config_t), intent(inout) :: cfg
    integer :: i, j
    do i = 1, cfg%n_materials
      call check_material(base, cfg%materials(i))
      do j = 1, i - 1
        if (cfg%materials(j)%name == cfg%materials(i)%name) call bad(base, 'material', &
          'name', "material '" // trim(cfg%materials(i)%name) // "' is defined twice")
      end do
    end do
    if (len_trim(cfg%base_material) == 0) call bad(base, 'domain', 'base_material', &
      "missing required value (a material name, or 'void')")
    call use_material(base, 'domain', 'base_material', cfg%base_material, 'void', cfg)
    do i = 1, cfg%n_bodies
      if (len_trim(cfg%bodies(i)%material) > 0) call use_material(base, 'body', 'material', &
        cfg%bodies(i)%material, 'void, rigid', cfg)
    end do
  end subroutine check_materials

  !> One material: its eos and the values that eos needs, its strength model (defaults
  !> filled in) and the values that model needs, and the range of every value given.
  subroutine check_material(base, m)
    character(len=*), intent(in) :: base
    type(material_t), intent(inout) :: m
    character(len=17) :: needs(8)
    character(len=:), allocatable :: in_m, model, why
    integer :: k, n_needs, n_before, n_start
    n_start = deck_error_count()
    ! a name that could not be read: which material this is, and so its values, is unknown
    if (len_trim(m%name) == 0 .and. deck_has_error('&material name')) return
    if (len_trim(m%name) == 0) call bad(base, 'material', 'name', 'missing required value')
    in_m = " in material '" // trim(m%name) // "'"
    if (.not. valid_name(m%name)) call bad(base, 'material', 'name', "'" // trim(m%name) &
      // "' is not a valid name (letters, digits, _ - . only)")
    if (m%name == 'void' .or. m%name == 'rigid') call bad(base, 'material', 'name', "'" &
      // trim(m%name) // "' is reserved (a body may use it without any &material)")
    if (len_trim(m%eos) == 0) call bad(base, 'material', 'eos', 'missing required value' &
      // in_m)
    call check_choice(base, 'material', 'eos', m%eos, eoses)
    select case (m%eos)
    ! a gas's rho0, p0 and cv are asked for only where the scene uses them (check_gas_needs)
    case ('ideal_gas')
      n_needs = 1
      needs(1:n_needs) = [character(len=17) :: 'gamma']
    case ('stiffened_gas')
      n_needs = 2
      needs(1:n_needs) = [character(len=17) :: 'gamma', 'p_inf']
    case ('mie_gruneisen')
      n_needs = 7
      needs(1:n_needs) = [character(len=17) :: 'rho0', 'p0', 'c0', 's', 'gruneisen', 'cv', &
        'T0']
    case default
      n_needs = 8
      needs(1:n_needs) = [character(len=17) :: 'rho0', 'p0', 'bulk_modulus', 'poly_a', &
        'poly_b', 'gruneisen', 'cv', 'T0']
    end select
    ! an unknown or missing eos needs nothing more
    if (deck_error_count() > n_start) n_needs = 0
    do k = 1, n_needs
      if (.not. is_set(material_value(m, needs(k)))) call bad(base, 'material', &
        trim(needs(k)), "missing required value for eos '" // trim(m%eos) // "'" // in_m)
    end do
    call at_least(m%rho0, 'rho0', .true., 0.0_wp)
    call at_least(m%gamma, 'gamma', .true., 1.0_wp)
    call at_least(m%p_inf, 'p_inf', .false., 0.0_wp)
    call at_least(m%c0, 'c0', .true., 0.0_wp)
    call at_least(m%s, 's', .false., 0.0_wp)
    call at_least(m%gruneisen, 'gruneisen', .false., 0.0_wp)
    call at_least(m%cv, 'cv', .true., 0.0_wp)
    call at_least(m%T0, 'T0', .true., 0.0_wp)
    if (m%eos == 'ideal_gas') call at_least(m%p0, 'p0', .false., 0.0_wp)
    if (m%eos == 'stiffened_gas') call at_least(m%p0, 'p0', .true., -m%p_inf)
    call at_least(m%bulk_modulus, 'bulk_modulus', .true., 0.0_wp)

    ! strength values without a model would be ignored without a word: refuse them
    if (len_trim(m%strength_model) == 0) then
      do k = 1, size(strength_values)
        if (is_set(material_value(m, strength_values(k)))) call bad(base, 'material', &
          'strength_model', 'missing required value' // in_m // ' (it gives ' &
          // trim(strength_values(k)) // "; set strength_model = 'none' to run without " &
          // 'strength)')
      end do
      m%strength_model = 'none'
    end if
    n_before = deck_error_count()
    call check_choice(base, 'material', 'strength_model', m%strength_model, strength_models)
    model = trim(m%strength_model)
    if (model /= 'none' .and. in_list(m%eos, gas_eoses)) call bad(base, 'material', &
      'strength_model', "'" // model // "' needs the eos of a solid (mie_gruneisen or " &
      // "polynomial_mie_gruneisen), not '" // trim(m%eos) // "'" // in_m)
    if (in_list(model, plastic_models) .and. .not. is_set(m%taylor_quinney)) &
      m%taylor_quinney = default_taylor_quinney
    if (model == 'johnson_cook' .and. .not. is_set(m%eps_rate0)) m%eps_rate0 = default_eps_rate0
    select case (model)
    case ('none')
      n_needs = 0
    case ('elastic')
      n_needs = 1
      needs(1:n_needs) = [character(len=17) :: 'shear_modulus']
    case ('perfectly_plastic')
      n_needs = 2
      needs(1:n_needs) = [character(len=17) :: 'shear_modulus', 'yield0']
    case ('linear_hardening')
      n_needs = 3
      needs(1:n_needs) = [character(len=17) :: 'shear_modulus', 'yield0', &
        'hardening_modulus']
    case ('johnson_cook')
      n_needs = 8
      needs(1:n_needs) = [character(len=17) :: 'shear_modulus', 'yield0', 'jc_b', 'jc_n', &
        'jc_c', 'jc_m', 't_melt', 'eps_rate0']
    case default
      n_needs = 5
      needs(1:n_needs) = [character(len=17) :: 'shear_modulus', 'yield0', 'vp_chi', 'vp_m', &
        'vp_n']
    end select
    if (deck_error_count() > n_before) n_needs = 0
    do k = 1, n_needs
      if (.not. is_set(material_value(m, needs(k)))) call bad(base, 'material', &
        trim(needs(k)), "missing required value for strength_model '" // model // "'" // in_m)
    end do
    call at_least(m%shear_modulus, 'shear_modulus', .true., 0.0_wp)
    ! a perfectly plastic solid without a yield stress is a fluid
    call at_least(m%yield0, 'yield0', model == 'perfectly_plastic', 0.0_wp)
    call at_least(m%hardening_modulus, 'hardening_modulus', .false., 0.0_wp)
    call at_least(m%jc_b, 'jc_b', .false., 0.0_wp)
    call at_least(m%jc_n, 'jc_n', .true., 0.0_wp)
    call at_least(m%jc_c, 'jc_c', .false., 0.0_wp)
    call at_least(m%jc_m, 'jc_m', .true., 0.0_wp)
    if (is_set(m%T0)) then
      if (is_set(m%t_melt) .and. .not. m%t_melt > m%T0) call bad(base, 'material', 't_melt', &
        'must be > T0 = ' // real_text(m%T0) // in_m // ', got ' // real_text(m%t_melt))
    else
      call at_least(m%t_melt, 't_melt', .true., 0.0_wp)
    end if
    call at_least(m%eps_rate0, 'eps_rate0', .true., 0.0_wp)
    call at_least(m%vp_chi, 'vp_chi', .true., 0.0_wp)
    call at_least(m%vp_n, 'vp_n', .true., 0.0_wp)
    ! m < 1: the flow stress then grows with the plastic rate, and the return has one root
    if (is_set(m%vp_m) .and. .not. m%vp_m < 1.0_wp) call bad(base, 'material', 'vp_m', &
      'must be < 1.0' // in_m // ', got ' // real_text(m%vp_m))
    if (is_set(m%taylor_quinney)) then
      if (m%taylor_quinney < 0.0_wp .or. m%taylor_quinney > 1.0_wp) call bad(base, &
        'material', 'taylor_quinney', 'must lie in [0, 1] (the share of plastic work ' &
        // 'that heats)' // in_m // ', got ' // real_text(m%taylor_quinney))
    end if
    ! the strength modules' own test of the parameters, should it know more than the above
    if (deck_error_count() > n_start) return
    why = strength_problem(strength_from_material(m))
    if (len_trim(why) > 0) call bad(base, 'material', 'strength_model', trim(why) // in_m)

  contains

    !> x (when set) must be > bound (strict) or >= bound.
    subroutine at_least(x, name, strict, bound)
      real(wp), intent(in) :: x, bound
      character(len=*), intent(in) :: name
      logical, intent(in) :: strict
      logical :: ok
      if (.not. is_set(x)) return
      if (strict) then
        ok = x > bound
      else
        ok = x >= bound
      end if
      if (.not. ok) call bad(base, 'material', name, 'must be ' &
        // trim(merge('> ', '>=', strict)) // ' ' // real_text(bound) // in_m // ', got ' &
        // real_text(x))
    end subroutine at_least

  end subroutine check_material

  !> What a gas in use needs besides its eos constants, asked for only where the scene uses
  !> it: cv where a temperature is used (the output field T, a body given by T; left out of
  !> the default fields otherwise); rho0 (p0) where the gas fills cells whose state no body
  !> gives: a body of it without rho (without p or T), the base material outside boxes of
  !> it that tile the domain, and every phase of a scene with level sets (the rest state of
  !> cells beyond a phase's region).
  subroutine check_gas_needs(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    character(len=:), allocatable :: in_m, why_t, why_rho, why_p
    logical :: fields_given, interfaces, drop_t
    integer :: k, i
    fields_given = given(groups, n_groups, 'output', 'fields')
    interfaces = any([(cfg%bodies(i)%material /= cfg%base_material, i = 1, cfg%n_bodies)])
    drop_t = .false.
    do k = 1, cfg%n_materials
      associate(m => cfg%materials(k))
        if (.not. in_list(m%eos, gas_eoses) .or. .not. material_used(cfg, m%name)) cycle
        in_m = " in material '" // trim(m%name) // "'"
        why_t = ''
        why_rho = ''
        why_p = ''
        if (fields_given .and. any(cfg%fields(1:cfg%n_fields) == 'T')) &
          why_t = 'the output field T'
        if (interfaces) then
          why_rho = 'the rest state of a scene with level sets'
          why_p = why_rho
        end if
        if (m%name == cfg%base_material .and. .not. base_covered(cfg)) then
          why_rho = 'the base material outside its bodies'
          why_p = why_rho
        end if
        do i = 1, cfg%n_bodies
          associate(b => cfg%bodies(i))
            if (b%material /= m%name) cycle
            if (is_set(b%T)) why_t = "body '" // trim(b%name) // "', given by T"
            if (.not. is_set(b%rho)) why_rho = "body '" // trim(b%name) // "' without rho"
            if (.not. is_set(b%p) .and. .not. is_set(b%T)) &
              why_p = "body '" // trim(b%name) // "' without p or T"
          end associate
        end do
        if (.not. is_set(m%cv) .and. len(why_t) > 0) call bad(base, 'material', 'cv', &
          "missing required value for eos '" // trim(m%eos) // "'" // in_m // ' (' // why_t &
          // ' needs a temperature)')
        if (.not. is_set(m%cv)) drop_t = .true.
        if (.not. is_set(m%rho0) .and. len(why_rho) > 0) call bad(base, 'material', 'rho0', &
          "missing required value for eos '" // trim(m%eos) // "'" // in_m // ' (for ' &
          // why_rho // ')')
        if (.not. is_set(m%p0) .and. len(why_p) > 0) call bad(base, 'material', 'p0', &
          "missing required value for eos '" // trim(m%eos) // "'" // in_m // ' (for ' &
          // why_p // ')')
      end associate
    end do
    ! the default fields without a temperature that some gas in use cannot give
    if (drop_t .and. .not. fields_given) then
      cfg%fields(1:cfg%n_fields - 1) = pack(cfg%fields(1:cfg%n_fields), &
        cfg%fields(1:cfg%n_fields) /= 'T')
      cfg%fields(cfg%n_fields) = ''
      cfg%n_fields = cfg%n_fields - 1
    end if
  end subroutine check_gas_needs

  !> Whether the boxes of the base material (bodies that only set its initial state) cover
  !> the whole domain: every cell of the grid that the boxes' faces make is inside one.
  pure logical function base_covered(cfg) result(covered)
    type(config_t), intent(in) :: cfg
    real(wp) :: edges(2 * cfg%n_bodies + 2, 3), x(3)
    integer :: n(3), d, i, c(3), ii, jj, kk
    logical :: inside
    covered = .false.
    n = 1
    do d = 1, cfg%ndim
      edges(1:2, d) = [cfg%lo(d), cfg%hi(d)]
      n(d) = 2
      do i = 1, cfg%n_bodies
        associate(b => cfg%bodies(i))
          if (b%material /= cfg%base_material .or. b%shape /= 'box') cycle
          edges(n(d) + 1:n(d) + 2, d) = [max(cfg%lo(d), min(cfg%hi(d), b%lo(d))), &
            max(cfg%lo(d), min(cfg%hi(d), b%hi(d)))]
          n(d) = n(d) + 2
        end associate
      end do
      n(d) = n(d) - 1
    end do
    do d = cfg%ndim + 1, 3
      edges(1:2, d) = [cfg%lo(d), cfg%hi(d)]
    end do
    do kk = 1, n(3)
      do jj = 1, n(2)
        do ii = 1, n(1)
          c = [ii, jj, kk]
          ! the centre of the span between two neighbouring edges (sorted on the fly)
          do d = 1, 3
            x(d) = span_centre(edges(1:n(d) + 1, d), c(d))
          end do
          if (.not. all(x(1:cfg%ndim) > cfg%lo(1:cfg%ndim))) cycle   ! an empty span
          inside = .false.
          do i = 1, cfg%n_bodies
            associate(b => cfg%bodies(i))
              if (b%material /= cfg%base_material .or. b%shape /= 'box') cycle
              if (all(x(1:cfg%ndim) > b%lo(1:cfg%ndim) .and. x(1:cfg%ndim) < b%hi(1:cfg%ndim))) &
                inside = .true.
            end associate
          end do
          if (.not. inside) return
        end do
      end do
    end do
    covered = .true.

  contains

    !> the midpoint between the c-th and (c+1)-th smallest of e, or lo - 1 when they are equal
    pure real(wp) function span_centre(e, c) result(xc)
      real(wp), intent(in) :: e(:)
      integer, intent(in) :: c
      real(wp) :: s(size(e)), t
      integer :: p, q
      s = e
      do p = 2, size(s)
        t = s(p)
        q = p - 1
        do while (q >= 1)
          if (s(q) <= t) exit
          s(q + 1) = s(q)
          q = q - 1
        end do
        s(q + 1) = t
      end do
      xc = 0.5_wp * (s(c) + s(c + 1))
      if (.not. s(c + 1) > s(c)) xc = -huge(1.0_wp)
    end function span_centre

  end function base_covered

  !> The &physics switches strength and thermal. Left out, each is on exactly when a
  !> material in use (the base material or a body's) needs it: strength when one has a
  !> strength_model other than 'none'; thermal, with strength on, when one softens with
  !> temperature (johnson_cook) or heats by plastic work (a plastic model with
  !> taylor_quinney > 0). Set to .false., the effect is off even if a material has it; set to
  !> .true., some material in use must need it. Stress and plastic-strain output fields need
  !> strength on.
  subroutine check_physics(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    logical :: needs_strength, needs_thermal
    integer :: k
    needs_strength = .false.
    needs_thermal = .false.
    do k = 1, cfg%n_materials
      associate(m => cfg%materials(k))
        if (.not. material_used(cfg, m%name)) cycle
        if (m%strength_model /= 'none') needs_strength = .true.
        if (m%strength_model == 'johnson_cook') needs_thermal = .true.
        if (in_list(m%strength_model, plastic_models)) then
          if (m%taylor_quinney > 0.0_wp) needs_thermal = .true.
        end if
      end associate
    end do
    if (.not. given(groups, n_groups, 'physics', 'strength')) then
      cfg%strength = needs_strength
    else if (cfg%strength .and. .not. needs_strength) then
      call bad(base, 'physics', 'strength', ".true. but no material in use has a " &
        // "strength_model other than 'none' (leave strength out: it is on exactly when a " &
        // 'material needs it)')
    end if
    needs_thermal = needs_thermal .and. cfg%strength
    if (.not. given(groups, n_groups, 'physics', 'thermal')) then
      cfg%thermal = needs_thermal
    else if (cfg%thermal .and. .not. needs_thermal) then
      if (.not. cfg%strength) then
        call bad(base, 'physics', 'thermal', '.true. but strength is off, so there is ' &
          // 'neither plastic heating nor thermal softening (leave thermal out)')
      else
        call bad(base, 'physics', 'thermal', '.true. but no material in use softens with ' &
          // 'temperature (johnson_cook) or heats by plastic work (taylor_quinney > 0) ' &
          // '(leave thermal out: it is on exactly when a material needs it)')
      end if
    end if
    if (cfg%strength) then
      ! the default fields of a scene with strength show its plastic strain and stress too
      if (.not. given(groups, n_groups, 'output', 'fields')) then
        cfg%fields(cfg%n_fields + 1:cfg%n_fields + 2) = [character(len=name_len) :: &
          'eps_p', 'seq']
        cfg%n_fields = cfg%n_fields + 2
      end if
      return
    end if
    do k = 1, cfg%n_fields
      if (in_list(cfg%fields(k), strength_fields)) call bad(base, 'output', 'fields', &
        "field '" // trim(cfg%fields(k)) // "' needs strength, which is off (no material " &
        // 'in use has a strength_model, or &physics strength = .false.)')
    end do
  end subroutine check_physics

  !> Whether the base material or a body uses the material called name.
  pure logical function material_used(cfg, name)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: name
    integer :: i
    material_used = (cfg%base_material == name)
    do i = 1, cfg%n_bodies
      if (cfg%bodies(i)%material == name) material_used = .true.
    end do
  end function material_used

  !> A material that the deck uses by name: defined, built in (then added), or one of the
  !> special names allowed at that place.
  subroutine use_material(base, gname, vname, name, special, cfg)
    character(len=*), intent(in) :: base, gname, vname, name, special
    type(config_t), intent(inout) :: cfg
    type(material_t) :: mat
    character(len=:), allocatable :: built_in
    logical :: found
    if (in_list(name, special)) return
    if (material_index(cfg, name) > 0) return
    call library_lookup(trim(name), mat, found)
    if (found) then
      if (cfg%n_materials == max_materials) call fail(base, '&material', 'more than ' &
        // int_text(max_materials) // ' materials with the built-in ones used (max_materials' &
        // ' of m_config)', '')
      cfg%n_materials = cfg%n_materials + 1
      ! the library's own entries pass the same checks and get the same defaults
      call check_material(base, mat)
      cfg%materials(cfg%n_materials) = mat
    else
      call library_names(built_in)
      call bad(base, gname, vname, "'" // trim(name) // "' is neither defined by a " &
        // '&material group nor built in (built in: ' // built_in // '; or ' // special // ')')
    end if
  end subroutine use_material

  subroutine check_bodies(base, cfg)
    character(len=*), intent(in) :: base
    type(config_t), intent(inout) :: cfg
    type(material_t) :: m
    character(len=:), allocatable :: in_b
    integer :: i, j, d
    do i = 1, cfg%n_bodies
      associate(b => cfg%bodies(i))
        if (len_trim(b%name) == 0) b%name = 'body' // int_text(i)
        in_b = " in body '" // trim(b%name) // "'"
        if (.not. valid_name(b%name)) call bad(base, 'body', 'name', "'" // trim(b%name) &
          // "' is not a valid name (letters, digits, _ - . only)")
        do j = 1, i - 1
          if (cfg%bodies(j)%name == b%name) call bad(base, 'body', 'name', "body '" &
            // trim(b%name) // "' is defined twice")
        end do
        if (len_trim(b%material) == 0) call bad(base, 'body', 'material', &
          'missing required value' // in_b)
        if (len_trim(b%shape) == 0) call bad(base, 'body', 'shape', &
          'missing required value' // in_b)
        call check_choice(base, 'body', 'shape', b%shape, shapes)
        select case (b%shape)
        case ('box')
          do d = 1, cfg%ndim
            if (.not. b%hi(d) > b%lo(d)) call bad(base, 'body', 'hi(' // int_text(d) // ')', &
              'must be > lo(' // int_text(d) // ') = ' // real_text(b%lo(d)) // in_b &
              // ', got ' // real_text(b%hi(d)))
          end do
        case ('sphere', 'cylinder')
          if (.not. b%radius > 0.0_wp) call bad(base, 'body', 'radius', 'must be > 0 for a ' &
            // trim(b%shape) // in_b // ', got ' // real_text(b%radius))
        end select
        if (b%shape == 'cylinder' .and. .not. b%length > 0.0_wp) call bad(base, 'body', &
          'length', 'must be > 0 for a cylinder' // in_b // ', got ' // real_text(b%length))
        if ((b%shape == 'cylinder' .or. b%shape == 'half_space') &
          .and. .not. maxval(abs(b%axis)) > 0.0_wp) call bad(base, 'body', 'axis', &
          'must not be zero for a ' // trim(b%shape) // in_b)
        if (.not. abs(b%amplitude) < 1.0_wp) call bad(base, 'body', 'amplitude', &
          'must lie in (-1, 1) so that rho (1 + amplitude sin(2 pi k.x)) stays > 0' // in_b &
          // ', got ' // real_text(b%amplitude))
        if (b%material == 'void' .or. b%material == 'rigid') cycle
        if (material_index(cfg, b%material) == 0) cycle   ! an error already
        m = cfg%materials(material_index(cfg, b%material))
        if (is_set(b%p) .and. is_set(b%T)) call bad(base, 'body', 'T', &
          'set p or T' // in_b // ', not both')
        if (.not. is_set(b%rho)) b%rho = m%rho0
        if (.not. is_set(b%p) .and. .not. is_set(b%T)) b%p = m%p0
        ! a gas without the rho0 or p0 that the body takes: reported by check_gas_needs
        if (.not. is_set(b%rho) .or. .not. (is_set(b%p) .or. is_set(b%T))) cycle
        if (.not. b%rho > 0.0_wp) call bad(base, 'body', 'rho', 'must be > 0' // in_b &
          // ', got ' // real_text(b%rho))
        if (is_set(b%T)) then
          if (.not. b%T > 0.0_wp) call bad(base, 'body', 'T', 'must be > 0' // in_b &
            // ', got ' // real_text(b%T))
        else if (m%eos == 'ideal_gas' .and. b%p < 0.0_wp) then
          call bad(base, 'body', 'p', 'must be >= 0 for a gas' // in_b // ', got ' &
            // real_text(b%p))
        else if (m%eos == 'stiffened_gas' .and. .not. b%p > -m%p_inf) then
          call bad(base, 'body', 'p', 'must be > -p_inf = ' // real_text(-m%p_inf) // in_b &
            // ', got ' // real_text(b%p))
        end if
      end associate
    end do
  end subroutine check_bodies

  real(wp) function material_value(m, name) result(x)
    type(material_t), intent(in) :: m
    character(len=*), intent(in) :: name
    select case (name)
    case ('rho0')
      x = m%rho0
    case ('p0')
      x = m%p0
    case ('gamma')
      x = m%gamma
    case ('p_inf')
      x = m%p_inf
    case ('c0')
      x = m%c0
    case ('s')
      x = m%s
    case ('gruneisen')
      x = m%gruneisen
    case ('cv')
      x = m%cv
    case ('bulk_modulus')
      x = m%bulk_modulus
    case ('poly_a')
      x = m%poly_a
    case ('poly_b')
      x = m%poly_b
    case ('shear_modulus')
      x = m%shear_modulus
    case ('yield0')
      x = m%yield0
    case ('hardening_modulus')
      x = m%hardening_modulus
    case ('jc_b')
      x = m%jc_b
    case ('jc_n')
      x = m%jc_n
    case ('jc_c')
      x = m%jc_c
    case ('jc_m')
      x = m%jc_m
    case ('t_melt')
      x = m%t_melt
    case ('eps_rate0')
      x = m%eps_rate0
    case ('vp_chi')
      x = m%vp_chi
    case ('vp_m')
      x = m%vp_m
    case ('vp_n')
      x = m%vp_n
    case ('taylor_quinney')
      x = m%taylor_quinney
    case default
      x = m%T0
    end select
  end function material_value

  subroutine check_choice(base, gname, vname, value, allowed)
    character(len=*), intent(in) :: base, gname, vname, value, allowed
    character(len=:), allocatable :: what
    integer :: paren
    if (in_list(value, allowed)) return
    paren = index(vname, '(')
    what = vname
    if (paren > 0) what = vname(1:paren - 1)
    if (what(1:min(3, len(what))) == 'bc_') what = 'bc'
    call fail(base, '&' // gname // ' ' // vname, 'unknown ' // what // " '" // trim(value) &
      // "' (allowed: " // allowed // ')', '')
  end subroutine check_choice

  !> Whether the first instance of group gname assigns variable vname.
  logical function given(groups, n_groups, gname, vname)
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    character(len=*), intent(in) :: gname, vname
    integer :: i, k
    given = .false.
    do i = 1, n_groups
      if (groups(i)%name /= gname) cycle
      do k = 1, groups(i)%n
        if (groups(i)%assign(k)%name == vname) given = .true.
      end do
      return
    end do
  end function given

  logical function valid_name(name)
    character(len=*), intent(in) :: name
    valid_name = len_trim(name) > 0 .and. verify(trim(name), 'abcdefghijklmnopqrstuvwxyz' &
      // 'ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.') == 0
  end function valid_name

end module m_deck_check
