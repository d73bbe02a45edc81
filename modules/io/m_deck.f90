!> The input deck (DESIGN section 6): deck_read reads a namelist deck plus command-line
!> overrides into a config_t, resolved and checked. Every rank parses the same text (read
!> once by rank 0 and broadcast), so every rank finds the same errors; each is reported
!> as one line
!>   ERROR <deck file> &<group> <variable>: <reason> (typical value <example>)
!> before anything is written, all of them in one run (a wrong value is skipped and the
!> reading goes on; m_deck_schema gathers the lines). The text is split by m_deck_parse;
!> each assignment is checked by m_deck_values and then read alone into the namelist of its
!> group, whose variables are locals of one routine per group (no module state; repeated
!> &material and &body groups start from defaults); m_deck_check then resolves and checks
!> the whole. deck_prepare_output
!> and deck_write_resolved (m_deck_write) are passed on, so that the driver needs only this
!> module. It does not interpret the physics: what a material or shape means is for eos/,
!> scene/.
module m_deck
  use m_kinds, only: wp, name_len, path_len, line_len
  use m_config, only: config_t, material_t, body_t, max_materials, max_bodies, max_fields
  use m_errors, only: stop_collective
  use m_comm, only: comm_bcast, comm_is_root
  use m_material_library, only: library_lookup
  use m_deck_text, only: to_lower, edit_distance, int_text, quoted, in_list, base_name
  use m_deck_parse, only: deck_assign_t, deck_group_t, deck_split, group_new, group_append
  use m_deck_values, only: var_info_t, check_value
  use m_deck_schema, only: known_groups, run_vars, domain_vars, numerics_vars, physics_vars, &
    material_vars, body_vars, output_vars, fail, error_line, group_vars, group_var, group_of, &
    var_index, fail_now, deck_errors_begin, deck_errors_stop, deck_error_mark
  use m_deck_check, only: deck_check
  use m_deck_write, only: deck_prepare_output, deck_write_resolved
  implicit none
  private
  public :: deck_read, deck_prepare_output, deck_write_resolved

contains

  !> Read the deck at `path` and the overrides (`group.var=value`, applied as if appended
  !> to the first instance of the group) into cfg, resolved and checked. Collective: call
  !> it on every rank; on an error all ranks stop with exit status 1.
  subroutine deck_read(path, overrides, cfg)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: overrides(:)
    type(config_t), intent(out) :: cfg
    character(len=:), allocatable :: text, base, msg, err_group, err_what
    type(deck_group_t), allocatable :: groups(:)
    integer :: n_groups
    logical :: ok

    call deck_errors_begin()
    base = base_name(path)
    text = ''
    msg = ''
    ok = .true.
    if (comm_is_root()) call read_text_file(path, text, ok, msg)
    call stop_collective(error_line(base, '', "cannot read the deck file '" // trim(path) &
      // "' (" // msg // ')', ''), ok)
    call comm_bcast(text, 0)

    call deck_split(text, groups, n_groups, err_group, err_what)
    if (len(err_what) > 0) then
      if (len(err_group) > 0) then
        call fail_now(base, '&' // err_group, err_what, '')
      else
        call fail_now(base, '', err_what, '')
      end if
    end if
    call apply_overrides(base, overrides, groups, n_groups)

    cfg%deck_file = path
    cfg%block = 0
    call read_groups(base, groups, n_groups, cfg)
    call deck_check(base, groups, n_groups, cfg)
    call deck_errors_stop()
  end subroutine deck_read

  subroutine read_text_file(path, text, ok, msg)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(inout) :: text, msg
    logical, intent(out) :: ok
    character(len=line_len) :: iomsg
    integer :: u, ios, n
    iomsg = ''
    open(newunit=u, file=trim(path), access='stream', form='unformatted', action='read', &
      status='old', iostat=ios, iomsg=iomsg)
    if (ios == 0) then
      inquire(unit=u, size=n)
      if (allocated(text)) deallocate(text)
      allocate(character(len=max(n, 0)) :: text)
      if (n > 0) read(u, iostat=ios, iomsg=iomsg) text
      close(u)
    end if
    ok = (ios == 0)
    msg = trim(iomsg)
  end subroutine read_text_file

  !> Turn each `group.var[(i)]=value` into an assignment appended to the first instance of
  !> the group (made if absent). Unquoted string values are quoted, since the shell eats
  !> the quotes of run.out_dir='x'.
  subroutine apply_overrides(base, overrides, groups, n_groups)
    character(len=*), intent(in) :: base
    character(len=*), intent(in) :: overrides(:)
    type(deck_group_t), allocatable, intent(inout) :: groups(:)
    integer, intent(inout) :: n_groups
    character(len=:), allocatable :: ov, gname, lhs
    type(deck_assign_t) :: a
    type(var_info_t) :: info
    integer :: i, j, k, eq, dot, paren

    do i = 1, size(overrides)
      ov = trim(adjustl(overrides(i)))
      if (len(ov) == 0) cycle
      eq = index(ov, '=')
      dot = 0
      if (eq > 1) dot = index(ov(1:eq - 1), '.')
      if (dot <= 1 .or. dot >= eq - 1) then
        call fail(base, '', "bad command-line override '" // ov &
          // "' (expected group.variable=value such as run.out_dir='out/x')", '')
        cycle
      end if
      gname = to_lower(trim(ov(1:dot - 1)))
      lhs = trim(adjustl(ov(dot + 1:eq - 1)))
      paren = index(lhs, '(')
      if (paren > 0) then
        a%name = to_lower(trim(lhs(1:paren - 1)))
        a%index = lhs(paren:)
        if (lhs(len(lhs):len(lhs)) /= ')') then
          call fail(base, '', "bad command-line override '" // ov &
            // "' (an index is written cells(2)=100)", '')
          cycle
        end if
      else
        a%name = to_lower(lhs)
        a%index = ''
      end if
      if (.not. in_list(gname, known_groups)) then
        call fail(base, '&' // gname, 'unknown group (known: ' // known_groups // ')', '')
        cycle
      end if
      k = var_index(group_vars(gname), a%name)
      if (k == 0) then
        call fail_unknown_var(base, gname, a%name, group_vars(gname))
        cycle
      end if
      a%value = trim(adjustl(ov(eq + 1:)))
      info = group_var(gname, k)
      if (info%kind == 'c') a%value = auto_quote(a%value)
      a%line = 0
      do j = 1, n_groups + 1
        if (j > n_groups) then
          call group_new(groups, n_groups, gname, 0)
          exit
        end if
        if (groups(j)%name == gname) exit
      end do
      call group_append(groups(j), a)
    end do
  end subroutine apply_overrides

  !> 'a,b' -> "'a', 'b'" unless the text is quoted already.
  function auto_quote(value) result(r)
    character(len=*), intent(in) :: value
    character(len=:), allocatable :: r, rest
    integer :: c
    if (len(value) > 0) then
      if (value(1:1) == "'" .or. value(1:1) == '"') then
        r = value
        return
      end if
    end if
    r = ''
    rest = value
    do
      c = index(rest, ',')
      if (c == 0) exit
      r = r // quoted(trim(adjustl(rest(1:c - 1)))) // ', '
      rest = rest(c + 1:)
    end do
    r = r // quoted(trim(adjustl(rest)))
  end function auto_quote

  !> Read every group in deck order into cfg (values only; checks come after).
  subroutine read_groups(base, groups, n_groups, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), intent(inout) :: cfg
    integer :: i, j
    do i = 1, n_groups
      select case (groups(i)%name)
      case ('run', 'domain', 'numerics', 'physics', 'output')
        do j = 1, i - 1
          if (groups(j)%name == groups(i)%name) call fail(base, '&' // groups(i)%name, &
            'group given twice (lines ' // int_text(groups(j)%line) // ' and ' &
            // int_text(groups(i)%line) // '); only &material and &body may repeat', '')
        end do
      end select
      select case (groups(i)%name)
      case ('run')
        call read_run(base, groups(i), cfg)
      case ('domain')
        call read_domain(base, groups(i), cfg)
      case ('numerics')
        call read_numerics(base, groups(i), cfg)
      case ('physics')
        call read_physics(base, groups(i), cfg)
      case ('output')
        call read_output(base, groups(i), cfg)
      case ('material')
        if (cfg%n_materials == max_materials) call fail_now(base, '&material', 'more than ' &
          // int_text(max_materials) // ' &material groups (max_materials of m_config)', '')
        cfg%n_materials = cfg%n_materials + 1
        call read_material(base, groups(i), cfg%materials(cfg%n_materials))
      case ('body')
        if (cfg%n_bodies == max_bodies) call fail_now(base, '&body', 'more than ' &
          // int_text(max_bodies) // ' &body groups (max_bodies of m_config)', '')
        cfg%n_bodies = cfg%n_bodies + 1
        call read_body(base, groups(i), cfg%bodies(cfg%n_bodies))
      case default
        call fail(base, '&' // groups(i)%name, 'unknown group (known: ' // known_groups &
          // ')', '')
        call mark_meant_group(groups(i)%name)
      end select
    end do
  end subroutine read_groups

  subroutine read_run(base, g, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(config_t), intent(inout) :: cfg
    character(len=128) :: title
    character(len=path_len) :: out_dir, restart
    real(wp) :: t_end, wall_limit
    integer :: max_steps, k, ios
    logical :: overwrite
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /run/ title, t_end, max_steps, wall_limit, out_dir, overwrite, restart
    title = cfg%title
    t_end = cfg%t_end
    max_steps = cfg%max_steps
    wall_limit = cfg%wall_limit
    out_dir = cfg%out_dir
    overwrite = cfg%overwrite
    restart = cfg%restart
    do k = 1, g%n
      rec = checked_record(base, g%name, run_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=run, iostat=ios, iomsg=msg)
      call check_read(base, g%name, run_vars, g%assign(k), ios, msg)
    end do
    cfg%title = title
    cfg%t_end = t_end
    cfg%max_steps = max_steps
    cfg%wall_limit = wall_limit
    cfg%out_dir = out_dir
    cfg%overwrite = overwrite
    cfg%restart = restart
  end subroutine read_run

  subroutine read_domain(base, g, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(config_t), intent(inout) :: cfg
    character(len=name_len) :: geometry, bc_lo(3), bc_hi(3), base_material
    real(wp) :: lo(3), hi(3), bc_velocity(3), bc_rise_time
    integer :: ndim, cells(3), block(3), k, ios
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /domain/ ndim, geometry, lo, hi, cells, block, bc_lo, bc_hi, bc_velocity, &
      bc_rise_time, base_material
    ndim = cfg%ndim
    geometry = cfg%geometry
    lo = cfg%lo
    hi = cfg%hi
    cells = cfg%cells
    block = cfg%block
    bc_lo = cfg%bc_lo
    bc_hi = cfg%bc_hi
    bc_velocity = cfg%bc_velocity
    bc_rise_time = cfg%bc_rise_time
    base_material = cfg%base_material
    do k = 1, g%n
      rec = checked_record(base, g%name, domain_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=domain, iostat=ios, iomsg=msg)
      call check_read(base, g%name, domain_vars, g%assign(k), ios, msg)
    end do
    cfg%ndim = ndim
    cfg%geometry = to_lower(geometry)
    cfg%lo = lo
    cfg%hi = hi
    cfg%cells = cells
    cfg%block = block
    cfg%bc_lo = to_lower(bc_lo)
    cfg%bc_hi = to_lower(bc_hi)
    cfg%bc_velocity = bc_velocity
    cfg%bc_rise_time = bc_rise_time
    cfg%base_material = base_material
  end subroutine read_domain

  subroutine read_numerics(base, g, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(config_t), intent(inout) :: cfg
    character(len=name_len) :: scheme, flux, scalar_flux, gfm_probe, surface_flux, conserve
    real(wp) :: cfl, dt_max, contact_kappa
    integer :: rk_order, reinit_every, band, k, ios
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /numerics/ scheme, flux, scalar_flux, rk_order, cfl, dt_max, gfm_probe, &
      reinit_every, band, contact_kappa, surface_flux, conserve
    scheme = cfg%scheme
    flux = cfg%flux
    scalar_flux = cfg%scalar_flux
    surface_flux = cfg%surface_flux
    conserve = cfg%conserve
    rk_order = cfg%rk_order
    cfl = cfg%cfl
    dt_max = cfg%dt_max
    gfm_probe = cfg%gfm_probe
    reinit_every = cfg%reinit_every
    band = cfg%band
    contact_kappa = cfg%contact_kappa
    do k = 1, g%n
      rec = checked_record(base, g%name, numerics_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=numerics, iostat=ios, iomsg=msg)
      call check_read(base, g%name, numerics_vars, g%assign(k), ios, msg)
    end do
    cfg%scheme = to_lower(scheme)
    cfg%flux = to_lower(flux)
    cfg%scalar_flux = to_lower(scalar_flux)
    cfg%surface_flux = to_lower(surface_flux)
    cfg%conserve = to_lower(conserve)
    cfg%rk_order = rk_order
    cfg%cfl = cfl
    cfg%dt_max = dt_max
    cfg%gfm_probe = to_lower(gfm_probe)
    cfg%reinit_every = reinit_every
    cfg%band = band
    cfg%contact_kappa = contact_kappa
  end subroutine read_numerics

  subroutine read_physics(base, g, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(config_t), intent(inout) :: cfg
    logical :: strength, thermal, heat_conduction, reaction
    integer :: k, ios
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /physics/ strength, thermal, heat_conduction, reaction
    strength = cfg%strength
    thermal = cfg%thermal
    heat_conduction = cfg%heat_conduction
    reaction = cfg%reaction
    do k = 1, g%n
      rec = checked_record(base, g%name, physics_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=physics, iostat=ios, iomsg=msg)
      call check_read(base, g%name, physics_vars, g%assign(k), ios, msg)
    end do
    cfg%strength = strength
    cfg%thermal = thermal
    cfg%heat_conduction = heat_conduction
    cfg%reaction = reaction
  end subroutine read_physics

  subroutine read_output(base, g, cfg)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(config_t), intent(inout) :: cfg
    character(len=name_len) :: fields(max_fields)
    real(wp) :: plot_dt
    integer :: plot_every, checkpoint_every, history_every, k, ios
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /output/ plot_dt, plot_every, checkpoint_every, history_every, fields
    plot_dt = cfg%plot_dt
    plot_every = cfg%plot_every
    checkpoint_every = cfg%checkpoint_every
    history_every = cfg%history_every
    fields = cfg%fields
    do k = 1, g%n
      rec = checked_record(base, g%name, output_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=output, iostat=ios, iomsg=msg)
      call check_read(base, g%name, output_vars, g%assign(k), ios, msg)
    end do
    cfg%plot_dt = plot_dt
    cfg%plot_every = plot_every
    cfg%checkpoint_every = checkpoint_every
    cfg%history_every = history_every
    cfg%fields = fields
  end subroutine read_output

  !> One &material group. The name is read first: a library entry of that name is the
  !> starting point that the other values of the group override.
  subroutine read_material(base, g, mat)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(material_t), intent(out) :: mat
    character(len=name_len) :: name, eos, strength_model
    real(wp) :: rho0, p0, gamma, p_inf, c0, s, gruneisen, cv, T0
    real(wp) :: bulk_modulus, poly_a, poly_b
    real(wp) :: shear_modulus, yield0, hardening_modulus, jc_b, jc_n, jc_c, jc_m, t_melt, &
      eps_rate0, vp_chi, vp_m, vp_n, taylor_quinney
    integer :: k, pass, ios
    logical :: found
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /material/ name, eos, rho0, p0, gamma, p_inf, c0, s, gruneisen, cv, T0, &
      bulk_modulus, poly_a, poly_b, strength_model, shear_modulus, yield0, &
      hardening_modulus, jc_b, jc_n, jc_c, jc_m, t_melt, eps_rate0, vp_chi, vp_m, vp_n, &
      taylor_quinney
    name = ''
    do pass = 1, 2
      if (pass == 2) then
        call library_lookup(name, mat, found)
        eos = mat%eos
        rho0 = mat%rho0
        p0 = mat%p0
        gamma = mat%gamma
        p_inf = mat%p_inf
        c0 = mat%c0
        s = mat%s
        gruneisen = mat%gruneisen
        cv = mat%cv
        T0 = mat%T0
        bulk_modulus = mat%bulk_modulus
        poly_a = mat%poly_a
        poly_b = mat%poly_b
        strength_model = mat%strength_model
        shear_modulus = mat%shear_modulus
        yield0 = mat%yield0
        hardening_modulus = mat%hardening_modulus
        jc_b = mat%jc_b
        jc_n = mat%jc_n
        jc_c = mat%jc_c
        jc_m = mat%jc_m
        t_melt = mat%t_melt
        eps_rate0 = mat%eps_rate0
        vp_chi = mat%vp_chi
        vp_m = mat%vp_m
        vp_n = mat%vp_n
        taylor_quinney = mat%taylor_quinney
      end if
      do k = 1, g%n
        if ((g%assign(k)%name == 'name') .neqv. (pass == 1)) cycle
        rec = checked_record(base, g%name, material_vars, g%assign(k))
        if (len(rec) == 0) cycle
        read(rec, nml=material, iostat=ios, iomsg=msg)
        call check_read(base, g%name, material_vars, g%assign(k), ios, msg)
      end do
    end do
    mat%name = name
    mat%eos = to_lower(eos)
    mat%rho0 = rho0
    mat%p0 = p0
    mat%gamma = gamma
    mat%p_inf = p_inf
    mat%c0 = c0
    mat%s = s
    mat%gruneisen = gruneisen
    mat%cv = cv
    mat%T0 = T0
    mat%bulk_modulus = bulk_modulus
    mat%poly_a = poly_a
    mat%poly_b = poly_b
    mat%strength_model = to_lower(strength_model)
    mat%shear_modulus = shear_modulus
    mat%yield0 = yield0
    mat%hardening_modulus = hardening_modulus
    mat%jc_b = jc_b
    mat%jc_n = jc_n
    mat%jc_c = jc_c
    mat%jc_m = jc_m
    mat%t_melt = t_melt
    mat%eps_rate0 = eps_rate0
    mat%vp_chi = vp_chi
    mat%vp_m = vp_m
    mat%vp_n = vp_n
    mat%taylor_quinney = taylor_quinney
  end subroutine read_material

  subroutine read_body(base, g, this)
    character(len=*), intent(in) :: base
    type(deck_group_t), intent(in) :: g
    type(body_t), intent(out) :: this
    character(len=name_len) :: name, material, shape
    real(wp) :: center(3), radius, length, axis(3), lo(3), hi(3), velocity(3), rho, p, T
    real(wp) :: amplitude, wavevector(3)
    integer :: k, ios
    character(len=:), allocatable :: rec
    character(len=line_len) :: msg
    namelist /body/ name, material, shape, center, radius, length, axis, lo, hi, velocity, &
      rho, p, T, amplitude, wavevector
    name = this%name
    material = this%material
    shape = this%shape
    center = this%center
    radius = this%radius
    length = this%length
    axis = this%axis
    lo = this%lo
    hi = this%hi
    velocity = this%velocity
    rho = this%rho
    p = this%p
    T = this%T
    amplitude = this%amplitude
    wavevector = this%wavevector
    do k = 1, g%n
      rec = checked_record(base, g%name, body_vars, g%assign(k))
      if (len(rec) == 0) cycle
      read(rec, nml=body, iostat=ios, iomsg=msg)
      call check_read(base, g%name, body_vars, g%assign(k), ios, msg)
    end do
    this%name = name
    this%material = material
    this%shape = to_lower(shape)
    this%center = center
    this%radius = radius
    this%length = length
    this%axis = axis
    this%lo = lo
    this%hi = hi
    this%velocity = velocity
    this%rho = rho
    this%p = p
    this%T = T
    this%amplitude = amplitude
    this%wavevector = wavevector
  end subroutine read_body

  !> The namelist record `&group name(index) = value /` of one assignment, once the name
  !> is known to the group and the value has the form of the variable; '' (the error
  !> recorded) otherwise.
  function checked_record(base, gname, vars, a) result(rec)
    character(len=*), intent(in) :: base, gname
    type(var_info_t), intent(in) :: vars(:)
    type(deck_assign_t), intent(in) :: a
    character(len=:), allocatable :: rec, why
    integer :: k
    rec = ''
    k = var_index(vars, a%name)
    if (k == 0) then
      call fail_unknown_var(base, gname, a%name, vars)
      return
    end if
    why = check_value(vars(k), a%index, a%value)
    if (len(why) > 0) then
      call fail(base, '&' // gname // ' ' // trim(vars(k)%name) // a%index, &
        why // at_line(a%line), vars(k)%typical)
      return
    end if
    rec = '&' // gname // ' ' // a%name // a%index // ' = ' // a%value // ' /'
  end function checked_record

  subroutine check_read(base, gname, vars, a, ios, msg)
    character(len=*), intent(in) :: base, gname, msg
    type(var_info_t), intent(in) :: vars(:)
    type(deck_assign_t), intent(in) :: a
    integer, intent(in) :: ios
    integer :: k
    if (ios == 0) return
    k = var_index(vars, a%name)
    call fail(base, '&' // gname // ' ' // trim(vars(k)%name) // a%index, 'cannot read ' &
      // a%value // at_line(a%line) // ' (' // trim(msg) // ')', vars(k)%typical)
  end subroutine check_read

  !> A misspelled group (&domian) is the group it was meant to be: the values missing there
  !> are the same mistake.
  subroutine mark_meant_group(name)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: rest, known
    integer :: c
    rest = known_groups // ','
    do
      c = index(rest, ',')
      if (c == 0) exit
      known = trim(adjustl(rest(1:c - 1)))
      rest = rest(c + 1:)
      if (edit_distance(name, known) <= 2) call deck_error_mark('&' // known // ' *')
    end do
  end subroutine mark_meant_group

  subroutine fail_unknown_var(base, gname, name, vars)
    character(len=*), intent(in) :: base, gname, name
    type(var_info_t), intent(in) :: vars(:)
    character(len=:), allocatable :: why, other
    integer :: k, d, best, best_d
    best = 0
    best_d = 3
    do k = 1, size(vars)
      d = edit_distance(name, to_lower(trim(vars(k)%name)))
      if (d < best_d) then
        best = k
        best_d = d
      end if
    end do
    other = group_of(name, gname)
    if (best > 0) then
      why = 'unknown variable, did you mean ' // trim(vars(best)%name) // '?'
    else if (len(other) > 0) then
      why = 'unknown variable here; ' // name // ' belongs in &' // other
    else
      why = 'unknown variable (known: ' // trim(vars(1)%name)
      do k = 2, size(vars)
        why = why // ', ' // trim(vars(k)%name)
      end do
      why = why // ')'
    end if
    call fail(base, '&' // gname // ' ' // name, why, '')
    ! the variable meant is then missing, but that is the same mistake
    if (best > 0) call deck_error_mark('&' // gname // ' ' // to_lower(trim(vars(best)%name)))
  end subroutine fail_unknown_var

  function at_line(line) result(r)
    integer, intent(in) :: line
    character(len=:), allocatable :: r
    if (line > 0) then
      r = ' at line ' // int_text(line)
    else
      r = ' on the command line'
    end if
  end function at_line

end module m_deck
