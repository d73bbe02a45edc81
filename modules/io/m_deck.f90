!> The input deck (DESIGN section 6). deck_read reads a namelist deck (read by rank 0,
!> parsed by every rank) plus command-line overrides into a config_t: each assignment is
!> found in m_deck_schema's table and read into the component its line points at (a repeated
!> &material or &body starts from defaults); m_deck_check resolves and checks the whole.
!> deck_write_resolved writes every value of the table, defaults filled in, so that reading
!> it back gives the same configuration bit for bit. No physics (eos/, scene/).
module m_deck
  use m_kinds, only: line_len
  use m_config, only: config_t, max_materials, max_bodies
  use m_errors, only: stop_collective, error_line
  use m_comm, only: comm_bcast, comm_is_root
  use m_material_library, only: library_lookup
  use m_text, only: int_text, base_name, file_text, to_lower, edit_distance, quoted, in_list, joined
  use m_deck_parse, only: deck_var_t, deck_assign_t, deck_group_t, deck_split, first_group, &
    assign_value, value_text
  use m_deck_schema, only: deck_table, group_table, group_names, var_index, fail, fail_now, &
    deck_errors_begin, deck_errors_stop, deck_error_mark
  use m_deck_check, only: deck_check
  implicit none
  private
  public :: deck_read, deck_write_resolved

contains

  !> Read the deck at `path` and the overrides (`group.var=value`, applied as if appended
  !> to the first instance of the group) into cfg, resolved and checked. Collective: call
  !> it on every rank; on an error all ranks stop with exit status 1.
  subroutine deck_read(path, overrides, cfg)
    character(len=*), intent(in) :: path
    character(len=*), intent(in) :: overrides(:)
    type(config_t), target, intent(out) :: cfg
    character(len=:), allocatable :: text, base, err_group, err_what
    character(len=line_len) :: msg
    type(deck_group_t), allocatable :: groups(:)
    type(deck_assign_t), allocatable :: assigns(:)
    integer :: ios

    base = base_name(path)
    call deck_errors_begin(base)
    text = ''
    ios = 0
    msg = ''
    if (comm_is_root()) call file_text(trim(path), text, ios, msg)
    call stop_collective(error_line(base, '', "cannot read the deck file '" // trim(path) &
      // "' (" // trim(msg) // ')', ''), ios == 0)
    call comm_bcast(text, 0)

    call deck_split(text, groups, assigns, err_group, err_what)
    ! a syntax error is named by its group ('&run'), if it is inside one
    if (len(err_what) > 0) call fail_now(repeat('&', min(1, len(err_group))) &
      // err_group, err_what, '')
    call apply_overrides(overrides, groups, assigns)
    cfg%deck_file = path
    call read_groups(groups, assigns, cfg)
    call deck_check(groups, assigns, cfg)
    call deck_errors_stop()
  end subroutine deck_read

  !> Turn each `group.var[(i)]=value` into an assignment appended to the first instance of
  !> the group (made if absent).
  subroutine apply_overrides(overrides, groups, assigns)
    character(len=*), intent(in) :: overrides(:)
    type(deck_group_t), allocatable, intent(inout) :: groups(:)
    type(deck_assign_t), allocatable, intent(inout) :: assigns(:)
    character(len=:), allocatable :: ov, gname, lhs, name, value, why
    integer :: i, eq, dot, paren
    do i = 1, size(overrides)
      ov = trim(adjustl(overrides(i)))
      eq = index(ov, '=')
      dot = index(ov(1:max(eq - 1, 0)), '.')
      lhs = trim(adjustl(ov(dot + 1:max(eq - 1, 0))))
      paren = index(lhs // '(', '(')
      if (len(ov) == 0) cycle
      why = ''
      if (paren <= len(lhs) .and. lhs(len(lhs):) /= ')') why = 'an index is written cells(2)=100'
      if (dot <= 1 .or. dot >= eq - 1) why = 'expected group.variable=value such as ' &
        // "run.out_dir='out/x'"
      if (len(why) > 0) then
        call fail('', "bad command-line override '" // ov // "' (" // why // ')', '')
        cycle
      end if
      gname = to_lower(trim(ov(1:dot - 1)))
      name = to_lower(trim(lhs(1:paren - 1)))
      value = trim(adjustl(ov(eq + 1:)))
      ! an unknown group or variable is reported when the group is read
      if (first_group(groups, gname) == 0) groups = [groups, deck_group_t(gname, 0)]
      assigns = [assigns, deck_assign_t(first_group(groups, gname), 0, name, lhs(paren:), value)]
    end do
  end subroutine apply_overrides

  !> 'a,b' -> "'a', 'b'"
  recursive function auto_quote(value) result(r)
    character(len=*), intent(in) :: value
    character(len=:), allocatable :: r
    integer :: c
    c = index(value // ',', ',')
    r = quoted(adjustl(value(1:c - 1)))
    if (c <= len(value)) r = r // ', ' // auto_quote(value(c + 1:))
  end function auto_quote

  !> Read every group in deck order into cfg (values only; checks come after). A &material
  !> reads its name first: a library entry of that name is the start that its other values
  !> override.
  subroutine read_groups(groups, assigns, cfg)
    type(deck_group_t), intent(in) :: groups(:)
    type(deck_assign_t), intent(in) :: assigns(:)
    type(config_t), target, intent(inout) :: cfg
    type(deck_var_t), allocatable :: vars(:)
    character(len=:), allocatable :: gname
    integer :: i, j, n
    logical :: found
    do i = 1, size(groups)
      gname = groups(i)%name
      j = first_group(groups, gname)
      if (.not. any(group_names == gname)) then
        call fail('&' // gname, 'unknown group (known: ' // joined(group_names) // ')', '')
        ! a misspelled group (&domian) is the group meant: the values missing there are
        ! the same mistake
        do j = 1, size(group_names)
          if (edit_distance(gname, trim(group_names(j))) <= 2) &
            call deck_error_mark('&' // trim(group_names(j)) // ' *')
        end do
        cycle
      else if (gname == 'material') then
        if (cfg%n_materials == max_materials) call fail_now('&material', 'more than ' &
          // int_text(max_materials) // ' &material groups (max_materials of m_config)', '')
        cfg%n_materials = cfg%n_materials + 1
      else if (gname == 'body') then
        if (cfg%n_bodies == max_bodies) call fail_now('&body', 'more than ' &
          // int_text(max_bodies) // ' &body groups (max_bodies of m_config)', '')
        cfg%n_bodies = cfg%n_bodies + 1
      else if (j < i) then
        call fail('&' // gname, 'group given twice (lines ' // int_text(groups(j)%line) &
          // ' and ' // int_text(groups(i)%line) // '); only &material and &body may repeat', '')
      end if
      ! the lines bound to the latest &material and &body (a new one starts from defaults)
      n = max(1, cfg%n_materials)
      call deck_table(cfg, cfg%materials(n), cfg%bodies(max(1, cfg%n_bodies)), vars)
      call read_group(i, merge(1, 0, gname == 'material'))
      if (gname /= 'material') cycle
      gname = cfg%materials(n)%name
      call library_lookup(gname, cfg%materials(n), found)
      cfg%materials(n)%name = gname
      call read_group(i, 2)
    end do

  contains

    !> Read the assignments of group g into the components that the table lines vars point
    !> at: all of them (pass 0), only that of `name` (1) or all others (2). Each is checked
    !> first: a name the group knows, a value of the variable's form, a keyword's choice.
    subroutine read_group(g, pass)
      integer, intent(in) :: g, pass
      character(len=:), allocatable :: why, where, at, value
      integer :: k, j
      vars = pack(vars, vars%group == groups(g)%name)
      do k = 1, size(assigns)
        associate(a => assigns(k))
          if (a%group /= g .or. (pass > 0 .and. ((a%name == 'name') .neqv. (pass == 1)))) cycle
          j = var_index(vars, a%name)
          if (j == 0) then
            call fail_unknown_var(groups(g)%name, a%name, vars)
            cycle
          end if
          where = '&' // groups(g)%name // ' ' // trim(vars(j)%name)
          at = ' on the command line'
          if (a%line > 0) at = ' at line ' // int_text(a%line)
          ! a list with a count (fields) given on the command line without an index
          ! replaces the deck's list, rather than only its first entries
          if (a%line == 0 .and. len(a%index) == 0 .and. associated(vars(j)%count) .and. &
            associated(vars(j)%ca)) vars(j)%ca = ''
          ! the shell eats the quotes of run.out_dir='x': a string there is quoted if it is not
          value = a%value
          if (a%line == 0 .and. index('ck', vars(j)%kind) > 0 .and. &
            scan(value(1:min(1, len(value))), "'""") == 0) value = auto_quote(value)
          why = assign_value(vars(j), a%index, value)
          if (len(why) > 0) then
            call fail(where // a%index, why // at, vars(j)%typical)
          else if (vars(j)%kind == 'k') then
            call check_choice(where, vars(j))
          end if
        end associate
      end do
    end subroutine read_group

  end subroutine read_groups

  !> A keyword must be one of its choices (or empty, where the table allows it).
  subroutine check_choice(where, v)
    character(len=*), intent(in) :: where
    type(deck_var_t), intent(in) :: v
    character(len=:), allocatable :: x, what
    integer :: k
    what = trim(v%name)
    if (what(1:min(3, len(what))) == 'bc_') what = 'bc'
    do k = 1, v%size
      if (associated(v%c)) x = trim(v%c)
      if (associated(v%ca)) x = trim(v%ca(k))
      if (in_list(x, v%choices) .or. (v%empty_ok .and. len(x) == 0)) cycle
      call fail(where // repeat('(' // int_text(k) // ')', merge(1, 0, associated(v%ca))), &
        'unknown ' // what // " '" // x // "' (allowed: " // v%choices // ')', '')
    end do
  end subroutine check_choice

  !> An unknown variable: the nearest name of the group, or the group it belongs in.
  subroutine fail_unknown_var(gname, name, vars)
    character(len=*), intent(in) :: gname, name
    type(deck_var_t), intent(in) :: vars(:)
    character(len=:), allocatable :: why
    type(deck_var_t), allocatable :: every(:)
    integer :: k, d(size(vars)), best, other
    d = [(edit_distance(name, to_lower(trim(vars(k)%name))), k = 1, size(vars))]
    best = minloc(d, 1)
    every = group_table('')   ! the first other group that knows the name
    other = findloc(to_lower(every%name) == name .and. every%group /= gname, .true., 1)
    if (d(best) < 3) then
      why = 'unknown variable, did you mean ' // trim(vars(best)%name) // '?'
    else if (other > 0) then
      why = 'unknown variable here; ' // name // ' belongs in &' // trim(every(other)%group)
    else
      why = 'unknown variable (known: ' // joined(vars%name) // ')'
    end if
    call fail('&' // gname // ' ' // name, why, '')
    ! the variable meant is then missing, but that is the same mistake
    if (d(best) < 3) call deck_error_mark('&' // gname // ' ' // to_lower(trim(vars(best)%name)))
  end subroutine fail_unknown_var

  !> Write cfg as a deck: every group, every variable of the table in its order, defaults
  !> filled in; deck_read gives back the same cfg. Reals left unset on purpose are written as
  !> comments. Plain I/O on the calling rank; ios receives the status.
  subroutine deck_write_resolved(cfg, path, ios)
    type(config_t), intent(in) :: cfg
    character(len=*), intent(in) :: path
    integer, intent(out) :: ios
    type(config_t), target, allocatable :: c
    type(deck_var_t), allocatable :: vars(:)
    character(len=:), allocatable :: line
    integer :: u, i, k, g
    open(newunit=u, file=trim(path), status='replace', action='write', iostat=ios)
    if (ios /= 0) return
    write(u, '(a)') '! Resolved SABRE deck: every value of ' // trim(cfg%deck_file) &
      // ' with the defaults filled in.'
    c = cfg
    do g = 1, size(group_names)
      do i = 1, merge(c%n_materials, merge(c%n_bodies, 1, group_names(g) == 'body'), &
        group_names(g) == 'material')
        call deck_table(c, c%materials(min(i, max_materials)), c%bodies(min(i, max_bodies)), vars)
        write(u, '(a)') '&' // trim(group_names(g))
        do k = 1, size(vars)
          if (vars(k)%group /= group_names(g)) cycle
          line = '  ' // trim(vars(k)%name) // ' = ' // value_text(vars(k))
          if (len(value_text(vars(k))) == 0) line = '  ! ' // trim(vars(k)%name) // ' is unset'
          write(u, '(a)') line
        end do
        write(u, '(a)') '/'
      end do
    end do
    close(u, iostat=ios)
  end subroutine deck_write_resolved

end module m_deck
