!> Resolving and checking a deck once it is read (DESIGN section 6). Resolving: materials
!> from the library where used, block sizes, a body's rho and p from its material, the output
!> fields (m_plot_fields), a model's defaults, the &physics switches left out (materials.md).
!> Checking: rules of one line each, `call rule(<prohibited>, '<group> <variable>', '<why>')`,
!> in a fixed order; a check that would only repeat an error already found is left out.
!> Choices and the form of each value were checked when it was read (m_deck).
module m_deck_check
  use m_kinds, only: wp
  use m_config, only: config_t, material_t, is_set, max_materials, material_index
  use m_material_library, only: library_lookup, library_names
  use m_yield, only: strength_problem, strength_from_material, strength_model_names, &
    strength_model_needs, strength_resolve, strength_rules, strength_thermal
  use m_reaction, only: reaction_rules
  use m_eos, only: eos_names, eos_needs, gas_p_rule, is_gas_eos
  use m_text, only: int_text, in_list, got_text
  use m_deck_parse, only: deck_var_t, deck_group_t, deck_assign_t, first_group
  use m_deck_schema, only: rule, deck_table, var_index, n_deck_errors, deck_has_error, &
    deck_error_mark
  use m_numerics_defaults, only: numerics_defaults
  use m_layout, only: layout_check
  use m_boundary, only: bc_check
  use m_scene, only: state_needs, body_check
  use m_plot_fields, only: fields_resolve
  implicit none
  private
  public :: deck_check

contains

  !> Resolve and check cfg as read from groups.
  subroutine deck_check(groups, assigns, cfg)
    type(deck_group_t), intent(in) :: groups(:)
    type(deck_assign_t), intent(in) :: assigns(:)
    type(config_t), target, intent(inout) :: cfg
    type(deck_var_t), allocatable :: vars(:)
    logical :: temperature
    integer :: i
    ! the values of &run, &domain, &numerics and &output where their table lines allow
    call deck_table(cfg, cfg%materials(1), cfg%bodies(1), vars)
    call check_allowed(pack(vars, vars%group /= 'material' .and. vars%group /= 'body'), '')
    call rule(.not. is_set(cfg%t_end) .and. .not. given('run', 'max_steps'), 'run t_end', &
      'missing required value (give t_end or max_steps)')
    call rule(len_trim(cfg%out_dir) == 0, 'run out_dir', 'missing required value (it is empty)')
    call rule(cfg%rebalance_threshold < 0.0_wp .or. (cfg%rebalance_threshold > 0.0_wp .and. &
      cfg%rebalance_threshold < 1.0_wp), 'run rebalance_threshold', 'must be 0 (never migrate) ' &
      // 'or >= 1' // got_text(cfg%rebalance_threshold))
    call check_domain()
    ! &material: each, then the library entries that the base material and bodies use
    do i = 1, cfg%n_materials
      call check_material(cfg%materials(i))
      call check_name('material', cfg%materials(i)%name, any(cfg%materials(1:i - 1)%name &
        == cfg%materials(i)%name))
    end do
    call rule(len_trim(cfg%base_material) == 0, 'domain base_material', &
      "missing required value (a material name, or 'void')")
    call use_material('domain base_material', cfg%base_material, 'void')
    do i = 1, cfg%n_bodies
      if (len_trim(cfg%bodies(i)%material) > 0) call use_material('body material', &
        cfg%bodies(i)%material, 'void, rigid')
    end do
    call check_gas_needs(temperature)
    call check_physics()
    call fields_resolve(cfg%fields, cfg%n_fields, temperature, cfg%strength, cfg%reaction, rule)
    call check_bodies()
    call numerics_defaults(cfg, cfg%numerics_note)

  contains

    !> Whether the first instance of group gname assigns variable vname.
    logical function given(gname, vname)
      character(len=*), intent(in) :: gname, vname
      integer :: k
      given = any([(assigns(k)%group == first_group(groups, gname) .and. &
        assigns(k)%name == vname, k = 1, size(assigns))])
    end function given

    subroutine check_domain()
      integer :: nd
      logical :: axisymmetric
      nd = cfg%ndim
      call rule(.not. given('domain', 'ndim'), 'domain ndim', 'missing required value')
      ! without a &domain group at all, its other required values are the same mistake
      if (first_group(groups, 'domain') == 0) call deck_error_mark('&domain *')
      call rule(nd < 1 .or. nd > 3, 'domain ndim', 'must be 1, 2 or 3' // got_text(nd))
      ! the directions, cells and blocks mean nothing without a valid ndim
      if (deck_has_error('&domain ndim')) return
      axisymmetric = cfg%geometry == 'axisymmetric'
      call rule(axisymmetric .and. nd /= 2, 'domain geometry', "'axisymmetric' needs ndim = 2 " &
        // '(x = r, y = z), got ndim = ' // int_text(nd))
      call rule(axisymmetric .and. cfg%lo(1) < 0.0_wp, 'domain lo(1)', 'must be >= 0 in ' &
        // 'axisymmetric geometry (x is the radius)' // got_text(cfg%lo(1)))
      call rule(.not. given('domain', 'cells'), 'domain cells', 'missing required value')
      call rule(.not. given('domain', 'hi'), 'domain hi', 'missing required value')
      call layout_check(cfg%cells, cfg%block, cfg%lo, cfg%hi, nd, &
        deck_has_error('&domain cells'), rule)
      call bc_check(cfg%bc_lo, cfg%bc_hi, nd, rule)
      call rule(axisymmetric .and. .not. cfg%lo(1) > 0.0_wp .and. .not. deck_has_error( &
        '&domain lo') .and. cfg%bc_lo(1) /= 'symmetry', 'domain bc_lo(1)', "must be " &
        // "'symmetry' on the axis r = 0 (lo(1) = 0, axisymmetric), got '" &
        // trim(cfg%bc_lo(1)) // "'")
    end subroutine check_domain

    !> One material: its eos and the values that eos needs, its strength model (defaults
    !> filled in) and the values that model needs, and the range of every value given.
    subroutine check_material(m)
      type(material_t), target, intent(inout) :: m
      type(deck_var_t), allocatable :: vars(:)
      character(len=:), allocatable :: in_m, why
      integer :: k, ke, km, ks, kr, n_before, n_start
      n_start = n_deck_errors
      ! a name that could not be read: which material this is, and so its values, is unknown
      if (len_trim(m%name) == 0 .and. deck_has_error('&material name')) return
      call deck_table(cfg, m, cfg%bodies(1), vars)
      vars = pack(vars, vars%group == 'material')
      ks = var_index(vars, 'strength_model')   ! the eos lines before it, strength's after
      kr = var_index(vars, 'conductivity')     ! conduction's and reaction's lines from here
      call rule(len_trim(m%name) == 0, 'material name', 'missing required value')
      in_m = " in material '" // trim(m%name) // "'"
      call rule(m%name == 'void' .or. m%name == 'rigid', 'material name', "'" &
        // trim(m%name) // "' is reserved (a body may use it without any &material)")
      call rule(len_trim(m%eos) == 0, 'material eos', 'missing required value' // in_m)
      ke = findloc(eos_names, m%eos, 1)
      ! an unknown or missing eos needs nothing more
      if (n_deck_errors == n_start .and. ke > 0) &
        call need(vars, eos_needs(ke), "eos '" // trim(m%eos) // "'" // in_m)
      call check_allowed(vars(1:ks), in_m)
      call gas_p_rule('material p0', m%p0, m, in_m, rule)
      ! strength values (the table's lines after strength_model) without a model would be
      ! ignored without a word: refuse them
      if (len_trim(m%strength_model) == 0) then
        do k = ks + 1, kr - 1
          call rule(is_set(vars(k)%r), 'material strength_model', 'missing required value' &
            // in_m // ' (it gives ' // trim(vars(k)%name) // "; set strength_model = " &
            // "'none' to run without strength)")
        end do
        m%strength_model = 'none'
      end if
      n_before = n_deck_errors
      km = findloc(strength_model_names, m%strength_model, 1)
      call strength_resolve(m, is_gas_eos(m%eos), in_m, rule)
      if (n_deck_errors == n_before .and. km > 0) &
        call need(vars, strength_model_needs(km), "strength_model '" // trim(m%strength_model) &
          // "'" // in_m)
      call strength_rules(m, in_m, rule)
      ! vp_m < 1 (its line): the flow stress then grows with the rate, the return has one root
      call check_allowed(vars(ks + 1:), in_m)
      call reaction_rules(m, in_m, rule)
      ! conduction and reaction act on the temperature
      call rule((m%reaction /= 'none' .or. is_set(m%conductivity)) .and. .not. is_set(m%cv), &
        'material cv', 'missing required value (conduction and reaction need the ' &
        // 'temperature)' // in_m)
      ! the strength modules' own test of the parameters, should it know more than the above
      if (n_deck_errors > n_start .or. ke == 0 .or. km == 0) return
      why = strength_problem(strength_from_material(m))
      call rule(len_trim(why) > 0, 'material strength_model', trim(why) // in_m)
    end subroutine check_material

    !> A material that the deck uses by name: defined, built in (then added), or one of the
    !> special names allowed at that place.
    subroutine use_material(var, name, special)
      character(len=*), intent(in) :: var, name, special
      type(material_t), target :: mat
      character(len=:), allocatable :: built_in
      logical :: found
      if (in_list(name, special) .or. material_index(cfg, name) > 0) return
      call library_lookup(trim(name), mat, found)
      call library_names(built_in)
      call rule(.not. found, var, "'" // trim(name) // "' is neither defined by a " &
        // '&material group nor built in (built in: ' // built_in // '; or ' // special // ')')
      if (.not. found) return
      call rule(cfg%n_materials == max_materials, 'material', 'more than ' &
        // int_text(max_materials) // ' materials with the built-in ones used (max_materials' &
        // ' of m_config)')
      if (cfg%n_materials == max_materials) return
      ! the library's own entries pass the same checks and get the same defaults
      call check_material(mat)
      cfg%n_materials = cfg%n_materials + 1
      cfg%materials(cfg%n_materials) = mat
    end subroutine use_material

    !> What a gas in use needs besides its eos constants, asked for only where the scene
    !> uses it (m_scene's state_needs): cv where a temperature is used (the output field T, a
    !> body given by T; left out of the default fields otherwise), rho0 and p0 where the scene
    !> takes the gas's own state. temperature: whether every gas in use has a cv.
    subroutine check_gas_needs(temperature)
      logical, intent(out) :: temperature
      character(len=:), allocatable :: why_t, why_rho, why_p, what
      integer :: k
      temperature = .true.
      do k = 1, cfg%n_materials
        associate(m => cfg%materials(k))
          if (.not. is_gas_eos(m%eos) .or. .not. material_used(m%name)) cycle
          what = "missing required value for eos '" // trim(m%eos) // "' in material '" &
            // trim(m%name) // "'"
          why_t = ''
          if (any(cfg%fields == 'T')) why_t = 'the output field T'
          call state_needs(cfg%bodies(1:cfg%n_bodies), m%name, cfg%base_material, cfg%ndim, &
            cfg%lo, cfg%hi, why_rho, why_p, why_t)
          call rule(.not. is_set(m%cv) .and. len(why_t) > 0, 'material cv', what // ' (' &
            // why_t // ' needs a temperature)')
          if (.not. is_set(m%cv)) temperature = .false.
          call rule(.not. is_set(m%rho0) .and. len(why_rho) > 0, 'material rho0', what &
            // ' (for ' // why_rho // ')')
          call rule(.not. is_set(m%p0) .and. len(why_p) > 0, 'material p0', what // ' (for ' &
            // why_p // ')')
        end associate
      end do
    end subroutine check_gas_needs

    !> The &physics switches. Left out, each is on exactly when a material in use needs it:
    !> strength, a strength_model other than 'none'; thermal, with strength on, softening
    !> with temperature (johnson_cook) or plastic heating (taylor_quinney > 0); heat_conduction,
    !> a conductivity; reaction, a reaction. Set to .true., some material in use must need it.
    !> Not conduction or reaction with the cut-cell update, whose content would not take their
    !> sources (not built).
    subroutine check_physics()
      logical :: used(cfg%n_materials)
      integer :: k
      associate(m => cfg%materials(1:cfg%n_materials))
        used = [(material_used(m(k)%name), k = 1, size(m))]
        call switch('strength', cfg%strength, any(used .and. m%strength_model /= 'none'), &
          "has a strength_model other than 'none' (leave strength out: it is on exactly " &
          // 'when a material needs it)')
        call rule(cfg%thermal .and. .not. cfg%strength, 'physics thermal', '.true. but strength ' &
          // 'is off, so there is neither plastic heating nor thermal softening (leave thermal ' &
          // 'out)')
        call switch('thermal', cfg%thermal, cfg%strength .and. any(used .and. &
          strength_thermal(m)), 'softens with temperature (johnson_cook) or heats by plastic ' &
          // 'work (taylor_quinney > 0) (leave thermal out: it is on exactly when a material ' &
          // 'needs it)')
        call switch('heat_conduction', cfg%heat_conduction, any(used .and. &
          is_set(m%conductivity)), 'has a conductivity (HMX: 0.4 W/(m K))')
        call switch('reaction', cfg%reaction, any(used .and. m%reaction /= 'none' .and. &
          m%reaction /= ''), "has a reaction (HMX: reaction = 'henson', reaction_q = 5.5e6)")
      end associate
      call rule((cfg%heat_conduction .or. cfg%reaction) .and. cfg%conserve == 'cut_cell', &
        'numerics conserve', "'cut_cell' with heat conduction or reaction is not built (the " &
        // "cut cells' content does not take their sources; use 'mass_energy')")
    end subroutine check_physics

    !> A switch left out is on exactly when needed; given .true., it must be needed.
    subroutine switch(name, on, needed, why)
      character(len=*), intent(in) :: name, why
      logical, intent(inout) :: on
      logical, intent(in) :: needed
      if (.not. given('physics', name)) on = needed
      call rule(on .and. .not. needed, 'physics ' // name, '.true. but no material in use ' // why)
    end subroutine switch

    !> Whether the base material or a body uses the material called name.
    logical function material_used(name)
      character(len=*), intent(in) :: name
      material_used = cfg%base_material == name .or. &
        any(cfg%bodies(1:cfg%n_bodies)%material == name)
    end function material_used

    subroutine check_bodies()
      type(material_t) :: m
      character(len=:), allocatable :: in_b
      integer :: i
      do i = 1, cfg%n_bodies
        associate(b => cfg%bodies(i))
          if (len_trim(b%name) == 0) b%name = 'body' // int_text(i)
          in_b = " in body '" // trim(b%name) // "'"
          call check_name('body', b%name, any(cfg%bodies(1:i - 1)%name == b%name))
          call rule(len_trim(b%material) == 0, 'body material', 'missing required value' // in_b)
          call rule(len_trim(b%shape) == 0, 'body shape', 'missing required value' // in_b)
          call body_check(b, cfg%ndim, in_b, rule)
          call deck_table(cfg, cfg%materials(1), b, vars)
          call check_allowed(pack(vars, vars%group == 'body'), in_b)
          if (b%material == 'void' .or. b%material == 'rigid') cycle
          if (material_index(cfg, b%material) == 0) cycle   ! an error already
          m = cfg%materials(material_index(cfg, b%material))
          call rule(is_set(b%p) .and. is_set(b%T), 'body T', 'set p or T' // in_b // ', not both')
          if (.not. is_set(b%rho)) b%rho = m%rho0
          if (.not. is_set(b%p) .and. .not. is_set(b%T)) b%p = m%p0
          ! a gas without the rho0 or p0 that the body takes: reported by check_gas_needs
          if (.not. is_set(b%rho) .or. .not. (is_set(b%p) .or. is_set(b%T))) cycle
          call rule(.not. b%rho > 0.0_wp, 'body rho', 'must be > 0' // in_b // got_text(b%rho))
          if (is_set(b%T)) call rule(.not. b%T > 0.0_wp, 'body T', 'must be > 0' // in_b &
            // got_text(b%T))
          if (.not. is_set(b%T)) call gas_p_rule('body p', b%p, m, in_b, rule)
        end associate
      end do
    end subroutine check_bodies

  end subroutine deck_check

  !> Each value of list ('a, b', in the order of the table) must be set (vars: the
  !> material's lines).
  subroutine need(vars, list, what)
    type(deck_var_t), intent(in) :: vars(:)
    character(len=*), intent(in) :: list, what
    integer :: k
    do k = 1, size(vars)
      if (in_list(vars(k)%name, trim(list))) call rule(.not. is_set(vars(k)%r), 'material ' &
        // trim(vars(k)%name), 'missing required value for ' // what)
    end do
  end subroutine need

  !> Each value of the table lines vars that has a set value and an allowed range must lie
  !> in it (deck_table: `> a`, `>= a`, `< a`, `in (a, b]`, `a, b or c`, then a reason);
  !> in names the material or body (" in body 'ball'"), or is ''.
  subroutine check_allowed(vars, in)
    type(deck_var_t), intent(in) :: vars(:)
    character(len=*), intent(in) :: in
    character(len=:), allocatable :: a, got
    real(wp) :: x, lo, hi
    integer :: k, e
    logical :: ok
    do k = 1, size(vars)
      a = trim(vars(k)%allowed)
      if (len(a) == 0) cycle
      if (associated(vars(k)%r)) then
        if (.not. is_set(vars(k)%r)) cycle   ! (unset is not written: real_text would overflow)
        x = vars(k)%r
        got = got_text(x)
      else
        x = real(vars(k)%i, wp)
        got = got_text(vars(k)%i)
      end if
      if (a(1:1) == '>' .or. a(1:1) == '<') then
        read(a(scan(a, ' '):), *) lo
        ok = (a(1:2) == '> ' .and. x > lo) .or. (a(1:2) == '>=' .and. x >= lo) .or. &
          (a(1:2) == '< ' .and. x < lo)
      else if (a(1:3) == 'in ') then
        e = scan(a, ')]')
        read(a(5:e - 1), *) lo, hi
        ok = (x > lo .or. (a(4:4) == '[' .and. x >= lo)) .and. (x < hi .or. (a(e:e) == ']' &
          .and. x <= hi))
      else   ! a list of integers 'a, b or c'
        e = index(a, ' or ')
        ok = in_list(int_text(vars(k)%i), a(1:e - 1)) .or. int_text(vars(k)%i) == a(e + 4:)
      end if
      call rule(.not. ok, trim(vars(k)%group) // ' ' // trim(vars(k)%name), 'must be ' // a &
        // in // got)
    end do
  end subroutine check_allowed

  !> A material's or body's name: letters, digits, _ - . only, and not taken (twice: one before
  !> it in the deck has it).
  subroutine check_name(group, name, twice)
    character(len=*), intent(in) :: group, name
    logical, intent(in) :: twice
    call rule(verify(trim(name), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ' &
      // '0123456789_-.') > 0, group // ' name', "'" // trim(name) // "' is not a valid name " &
      // '(letters, digits, _ - . only)')
    call rule(twice, group // ' name', group // " '" // trim(name) &
      // "' is defined twice")
  end subroutine check_name

end module m_deck_check
