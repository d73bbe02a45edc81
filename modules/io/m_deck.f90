!> The input deck (DESIGN section 6): deck_read reads a namelist deck plus command-line
!> overrides into a config_t, resolved and checked. Every rank parses the same text (read
!> once by rank 0 and broadcast), so every rank finds the same errors; each is reported
!> as one line
!>   ERROR <deck file> &<group> <variable>: <reason> (typical value <example>)
!> before anything is written, all of them in one run (a wrong value is skipped and the
!> reading goes on; m_deck_schema gathers the lines). The text is split by m_deck_parse;
!> each assignment is found in the table of m_deck_schema, checked by m_deck_values and
!> read into the component its table line points at (repeated &material and &body groups
!> start from defaults); m_deck_check then resolves and checks the whole. deck_prepare_output
!> and deck_write_resolved (m_deck_write) are passed on, so that the driver needs only this
!> module. It does not interpret the physics: what a material or shape means is for eos/,
!> scene/.
module m_deck
  use m_kinds, only: line_len
  use m_config, only: config_t, max_materials, max_bodies
  use m_errors, only: stop_collective
  use m_comm, only: comm_bcast, comm_is_root
  use m_material_library, only: library_lookup
  use m_deck_text, only: to_lower, edit_distance, int_text, quoted, in_list, joined, base_name
  use m_deck_parse, only: deck_assign_t, deck_group_t, deck_split, group_new, group_append
  use m_deck_values, only: deck_var_t, check_value, read_value
  use m_deck_schema, only: deck_table, group_table, known_groups, group_names, var_index, &
    group_of, fail, fail_now, error_line, deck_errors_begin, deck_errors_stop, deck_error_mark
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
    type(config_t), target, intent(out) :: cfg
    character(len=:), allocatable :: text, base, msg, err_group, err_what
    type(deck_group_t), allocatable :: groups(:)
    integer :: n_groups
    logical :: ok

    base = base_name(path)
    call deck_errors_begin(base)
    text = ''
    msg = ''
    ok = .true.
    if (comm_is_root()) call read_text_file(path, text, ok, msg)
    call stop_collective(error_line(base, '', "cannot read the deck file '" // trim(path) &
      // "' (" // msg // ')', ''), ok)
    call comm_bcast(text, 0)

    call deck_split(text, groups, n_groups, err_group, err_what)
    ! a syntax error is named by its group ('&run'), if it is inside one
    if (len(err_what) > 0) call fail_now(repeat('&', min(1, len(err_group))) &
      // err_group, err_what, '')
    call apply_overrides(overrides, groups, n_groups)

    cfg%deck_file = path
    cfg%block = 0
    call read_groups(groups, n_groups, cfg)
    call deck_check(groups, n_groups, cfg)
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
  subroutine apply_overrides(overrides, groups, n_groups)
    character(len=*), intent(in) :: overrides(:)
    type(deck_group_t), allocatable, intent(inout) :: groups(:)
    integer, intent(inout) :: n_groups
    character(len=:), allocatable :: ov, gname, lhs
    type(deck_assign_t) :: a
    type(deck_var_t), allocatable :: vars(:)
    integer :: i, j, k, eq, dot, paren

    do i = 1, size(overrides)
      ov = trim(adjustl(overrides(i)))
      if (len(ov) == 0) cycle
      eq = index(ov, '=')
      dot = 0
      if (eq > 1) dot = index(ov(1:eq - 1), '.')
      if (dot <= 1 .or. dot >= eq - 1) then
        call fail('', "bad command-line override '" // ov &
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
          call fail('', "bad command-line override '" // ov &
            // "' (an index is written cells(2)=100)", '')
          cycle
        end if
      else
        a%name = to_lower(lhs)
        a%index = ''
      end if
      if (.not. in_list(gname, known_groups)) then
        call fail('&' // gname, 'unknown group (known: ' // known_groups // ')', '')
        cycle
      end if
      vars = group_table(gname)
      k = var_index(vars, a%name)
      if (k == 0) then
        call fail_unknown_var(gname, a%name, vars)
        cycle
      end if
      a%value = trim(adjustl(ov(eq + 1:)))
      if (vars(k)%kind == 'c' .or. vars(k)%kind == 'k') a%value = auto_quote(a%value)
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

  !> Read every group in deck order into cfg (values only; checks come after). A &material
  !> reads its name first: a library entry of that name is the start that its other values
  !> override.
  subroutine read_groups(groups, n_groups, cfg)
    type(deck_group_t), intent(in) :: groups(:)
    integer, intent(in) :: n_groups
    type(config_t), target, intent(inout) :: cfg
    type(deck_var_t), allocatable :: vars(:)
    character(len=:), allocatable :: gname
    integer :: i, j, n
    logical :: found
    do i = 1, n_groups
      gname = groups(i)%name
      select case (gname)
      case ('run', 'domain', 'numerics', 'physics', 'output')
        do j = 1, i - 1
          if (groups(j)%name == gname) call fail('&' // gname, 'group given twice ' &
            // '(lines ' // int_text(groups(j)%line) // ' and ' // int_text(groups(i)%line) &
            // '); only &material and &body may repeat', '')
        end do
        call deck_table(cfg, cfg%materials(1), cfg%bodies(1), vars)
        call read_group(groups(i), vars, 0)
      case ('material')
        if (cfg%n_materials == max_materials) call fail_now('&material', 'more than ' &
          // int_text(max_materials) // ' &material groups (max_materials of m_config)', '')
        n = cfg%n_materials + 1
        cfg%n_materials = n
        call deck_table(cfg, cfg%materials(n), cfg%bodies(1), vars)
        call read_group(groups(i), vars, 1)
        gname = cfg%materials(n)%name
        call library_lookup(gname, cfg%materials(n), found)
        cfg%materials(n)%name = gname
        call read_group(groups(i), vars, 2)
      case ('body')
        if (cfg%n_bodies == max_bodies) call fail_now('&body', 'more than ' &
          // int_text(max_bodies) // ' &body groups (max_bodies of m_config)', '')
        cfg%n_bodies = cfg%n_bodies + 1
        call deck_table(cfg, cfg%materials(1), cfg%bodies(cfg%n_bodies), vars)
        call read_group(groups(i), vars, 0)
      case default
        call fail('&' // gname, 'unknown group (known: ' // known_groups // ')', '')
        call mark_meant_group(gname)
      end select
    end do
  end subroutine read_groups

  !> Read the assignments of group g into the components that the table lines vars point
  !> at: all of them (pass 0), only those of `name` (1) or all others (2). Each is checked
  !> first: a name the group knows, a value of the variable's form, a keyword's choice.
  subroutine read_group(g, every, pass)
    type(deck_group_t), intent(in) :: g
    type(deck_var_t), intent(in) :: every(:)
    integer, intent(in) :: pass
    type(deck_var_t), allocatable :: vars(:)
    character(len=:), allocatable :: why, where
    character(len=line_len) :: msg
    integer :: k, j, ios
    vars = pack(every, every%group == g%name)
    do k = 1, g%n
      associate(a => g%assign(k))
        if (pass > 0 .and. ((a%name == 'name') .neqv. (pass == 1))) cycle
        j = var_index(vars, a%name)
        if (j == 0) then
          call fail_unknown_var(g%name, a%name, vars)
          cycle
        end if
        where = '&' // g%name // ' ' // trim(vars(j)%name)
        why = check_value(vars(j), a%index, a%value)
        if (len(why) > 0) then
          call fail(where // a%index, why // at_line(a%line), vars(j)%typical)
          cycle
        end if
        msg = ''
        call read_value(vars(j), a%index, a%value, ios, msg)
        if (ios /= 0) call fail(where // a%index, 'cannot read ' // a%value &
          // at_line(a%line) // ' (' // trim(msg) // ')', vars(j)%typical)
        if (vars(j)%kind == 'k') call check_choice(where, vars(j))
      end associate
    end do
  end subroutine read_group

  !> A keyword must be one of its choices (or empty, where the table allows it).
  subroutine check_choice(where, v)
    character(len=*), intent(in) :: where
    type(deck_var_t), intent(in) :: v
    integer :: k
    if (associated(v%c)) call one(v%c, '')
    if (associated(v%ca)) then
      do k = 1, size(v%ca)
        call one(v%ca(k), '(' // int_text(k) // ')')
      end do
    end if
  contains
    subroutine one(x, subscript)
      character(len=*), intent(in) :: x, subscript
      character(len=:), allocatable :: what
      if (in_list(x, v%choices) .or. (v%empty_ok .and. len_trim(x) == 0)) return
      what = trim(v%name)
      if (what(1:min(3, len(what))) == 'bc_') what = 'bc'
      call fail(where // subscript, 'unknown ' // what // " '" // trim(x) &
        // "' (allowed: " // v%choices // ')', '')
    end subroutine one
  end subroutine check_choice

  !> A misspelled group (&domian) is the group it was meant to be: the values missing there
  !> are the same mistake.
  subroutine mark_meant_group(name)
    character(len=*), intent(in) :: name
    integer :: k
    do k = 1, size(group_names)
      if (edit_distance(name, trim(group_names(k))) <= 2) &
        call deck_error_mark('&' // trim(group_names(k)) // ' *')
    end do
  end subroutine mark_meant_group

  subroutine fail_unknown_var(gname, name, vars)
    character(len=*), intent(in) :: gname, name
    type(deck_var_t), intent(in) :: vars(:)
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
      why = 'unknown variable (known: ' // joined(vars%name) // ')'
    end if
    call fail('&' // gname // ' ' // name, why, '')
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
