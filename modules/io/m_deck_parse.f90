!> The lexical side of deck reading (DESIGN section 6): it turns the text of a namelist deck
!> into groups (`&name ... /`) of single assignments (`name[(index)] = value-text`), each
!> with the line it came from. This is done by hand, before any namelist READ, so that every
!> complaint can name the group, the variable and the line, which gfortran's own namelist
!> reader cannot do; a syntax error comes back with the offending line echoed. It does not
!> check a value against its variable (m_deck_values), knows nothing of which groups and
!> variables exist (m_deck_schema) and never stops the run: it returns reasons.
module m_deck_parse
  use m_deck_text, only: to_lower, int_text, string_end, is_digit
  implicit none
  private
  public :: deck_assign_t, deck_group_t
  public :: deck_split, group_new, group_append

  !> One `name[(index)] = value` of a group; line 0 means it came from the command line.
  type :: deck_assign_t
    character(len=:), allocatable :: name    !< lower case
    character(len=:), allocatable :: index   !< '' or the index text with its parentheses
    character(len=:), allocatable :: value   !< the value text, blanks for line breaks
    integer :: line = 0
  end type deck_assign_t

  !> One `&name ... /` group in deck order; line 0 means it was made for an override.
  type :: deck_group_t
    character(len=:), allocatable :: name    !< lower case
    integer :: line = 0
    integer :: n = 0
    type(deck_assign_t), allocatable :: assign(:)
  end type deck_group_t

  character(len=1), parameter :: nl = achar(10)

contains

  !> Split deck text into groups. On a syntax error, err_what says what and where (with
  !> the offending line echoed), err_group names the group it happened in ('' outside any),
  !> and the groups found so far are returned.
  subroutine deck_split(text, groups, n_groups, err_group, err_what)
    character(len=*), intent(in) :: text
    type(deck_group_t), allocatable, intent(out) :: groups(:)
    integer, intent(out) :: n_groups
    character(len=:), allocatable, intent(out) :: err_group, err_what
    character(len=:), allocatable :: s, name, subscript, value
    integer :: n, p, q, after, close_at, value_end, name_at
    type(deck_assign_t) :: a

    allocate(groups(4))
    n_groups = 0
    err_group = ''
    err_what = ''
    call strip_comments(text, s)
    n = len(s)
    p = 1
    outer: do
      p = skip_space(s, p)
      if (p > n) exit outer
      if (s(p:p) /= '&') then
        call syntax(p, 'text outside a group; a group starts with &name and ends with /')
        return
      end if
      q = p + 1
      do while (q <= n)
        if (.not. is_name_char(s(q:q))) exit
        q = q + 1
      end do
      if (q == p + 1) then
        call syntax(p, "'&' without a group name")
        return
      end if
      call group_new(groups, n_groups, to_lower(s(p + 1:q - 1)), line_of(p))
      err_group = groups(n_groups)%name
      p = q
      body: do
        p = skip_space(s, p)
        if (p > n) then
          call not_closed(groups(n_groups)%line, 'the end of the file')
          return
        end if
        if (s(p:p) == '/') then
          p = p + 1
          exit body
        end if
        if (.not. assign_start(s, p, name, subscript, after)) then
          if (s(p:p) == '&') then
            call not_closed(groups(n_groups)%line, 'line ' // int_text(line_of(p)))
          else
            call syntax(p, 'expected name = value')
          end if
          return
        end if
        name_at = p
        p = after
        value_end = n
        scan_value: do
          if (p > n) then
            call not_closed(groups(n_groups)%line, 'the end of the file')
            return
          end if
          select case (s(p:p))
          case ("'", '"')
            close_at = string_end(s, p)
            if (close_at == 0) then
              call syntax(p, 'unterminated string')
              return
            end if
            p = close_at + 1
            cycle scan_value
          case ('/')
            value_end = p - 1
            exit scan_value
          case ('&')
            call not_closed(groups(n_groups)%line, 'line ' // int_text(line_of(p)))
            return
          case ('a':'z', 'A':'Z')
            if (index_separator(s(p - 1:p - 1))) then
              if (assign_start(s, p, a%name, a%index, q)) then
                value_end = p - 1
                exit scan_value
              end if
            end if
          end select
          p = p + 1
        end do scan_value
        value = s(after:value_end)
        do q = 1, len(value)
          if (value(q:q) == nl) value(q:q) = ' '
        end do
        value = trim(adjustl(value))
        ! a trailing comma only separates this value from the next name
        do while (len(value) > 0)
          if (value(len(value):len(value)) /= ',') exit
          value = trim(value(1:len(value) - 1))
        end do
        if (len(value) == 0) then
          call syntax(name_at, "no value after '='; give a value or remove the line")
          return
        end if
        a%name = to_lower(name)
        a%index = subscript
        a%value = value
        a%line = line_of(name_at)
        call group_append(groups(n_groups), a)
      end do body
      err_group = ''
    end do outer

  contains

    integer function line_of(pos)
      integer, intent(in) :: pos
      integer :: k
      line_of = 1 + count([(s(k:k) == nl, k = 1, pos - 1)])
    end function line_of

    !> line `line` of the text, fit to be echoed in a one-line message
    function line_text(line) result(t)
      integer, intent(in) :: line
      character(len=:), allocatable :: t
      integer :: a0, k
      a0 = 1
      do k = 2, line
        a0 = a0 + index(text(a0:), nl)
      end do
      t = text(a0:)
      if (index(t, nl) > 0) t = t(1:index(t, nl) - 1)
      t = trim(adjustl(t))
      do k = 1, len(t)
        if (iachar(t(k:k)) < 32 .or. iachar(t(k:k)) > 126) t(k:k) = '?'
      end do
      if (len(t) > 120) t = t(1:117) // '...'
    end function line_text

    subroutine syntax(pos, what)
      integer, intent(in) :: pos
      character(len=*), intent(in) :: what
      integer :: line
      line = line_of(pos)
      err_what = 'syntax error at line ' // int_text(line) // ' (' // what // '): ' &
        // line_text(line)
    end subroutine syntax

    subroutine not_closed(line, before)
      integer, intent(in) :: line
      character(len=*), intent(in) :: before
      err_what = 'syntax error: the group opened at line ' // int_text(line) &
        // " is not closed with '/' before " // before // ': ' // line_text(line)
    end subroutine not_closed

  end subroutine deck_split

  !> Append one assignment to a group.
  subroutine group_append(g, a)
    type(deck_group_t), intent(inout) :: g
    type(deck_assign_t), intent(in) :: a
    type(deck_assign_t), allocatable :: tmp(:)
    if (.not. allocated(g%assign)) allocate(g%assign(8))
    if (g%n == size(g%assign)) then
      allocate(tmp(2 * g%n))
      tmp(1:g%n) = g%assign(1:g%n)
      call move_alloc(tmp, g%assign)
    end if
    g%n = g%n + 1
    g%assign(g%n) = a
  end subroutine group_append

  !> Append an empty group called name (line 0: made for a command-line override).
  subroutine group_new(groups, n_groups, name, line)
    type(deck_group_t), allocatable, intent(inout) :: groups(:)
    integer, intent(inout) :: n_groups
    character(len=*), intent(in) :: name
    integer, intent(in) :: line
    if (.not. allocated(groups)) allocate(groups(4))
    if (n_groups == size(groups)) call grow_groups(groups)
    n_groups = n_groups + 1
    groups(n_groups)%name = name
    groups(n_groups)%line = line
    groups(n_groups)%n = 0
    allocate(groups(n_groups)%assign(8))
  end subroutine group_new

  subroutine grow_groups(groups)
    type(deck_group_t), allocatable, intent(inout) :: groups(:)
    type(deck_group_t), allocatable :: tmp(:)
    allocate(tmp(2 * size(groups)))
    tmp(1:size(groups)) = groups
    call move_alloc(tmp, groups)
  end subroutine grow_groups

  !> Copy of the text with comments, carriage returns and tabs blanked.
  subroutine strip_comments(text, s)
    character(len=*), intent(in) :: text
    character(len=:), allocatable, intent(out) :: s
    character(len=1) :: quote
    integer :: i
    logical :: in_comment
    s = text
    quote = ' '
    in_comment = .false.
    do i = 1, len(s)
      if (s(i:i) == nl) then
        quote = ' '
        in_comment = .false.
      else if (in_comment .or. s(i:i) == achar(13) .or. s(i:i) == achar(9)) then
        s(i:i) = ' '
      else if (quote /= ' ') then
        if (s(i:i) == quote) quote = ' '
      else if (s(i:i) == "'" .or. s(i:i) == '"') then
        quote = s(i:i)
      else if (s(i:i) == '!') then
        in_comment = .true.
        s(i:i) = ' '
      end if
    end do
  end subroutine strip_comments

  !> Does an assignment `name [(index)] =` start at p? If so return its parts and the
  !> position just after '='.
  logical function assign_start(s, p, name, subscript, after) result(yes)
    character(len=*), intent(in) :: s
    integer, intent(in) :: p
    character(len=:), allocatable, intent(inout) :: name, subscript
    integer, intent(out) :: after
    integer :: q, r, c
    yes = .false.
    after = p
    if (.not. is_letter(s(p:p))) return
    q = p
    do while (q <= len(s))
      if (.not. is_name_char(s(q:q))) exit
      q = q + 1
    end do
    r = skip_space(s, q)
    if (r > len(s)) return
    if (s(r:r) == '(') then
      c = r
      do while (c <= len(s))
        if (s(c:c) == ')' .or. s(c:c) == nl .or. s(c:c) == '=') exit
        c = c + 1
      end do
      if (c > len(s)) return
      if (s(c:c) /= ')') return
      subscript = compact(s(r:c))
      r = skip_space(s, c + 1)
      if (r > len(s)) return
    else
      subscript = ''
    end if
    if (s(r:r) /= '=') return
    name = s(p:q - 1)
    after = r + 1
    yes = .true.
  end function assign_start

  integer function skip_space(s, p) result(q)
    character(len=*), intent(in) :: s
    integer, intent(in) :: p
    q = p
    do while (q <= len(s))
      if (s(q:q) /= ' ' .and. s(q:q) /= nl) exit
      q = q + 1
    end do
  end function skip_space

  logical function index_separator(c)
    character(len=1), intent(in) :: c
    index_separator = (c == ' ' .or. c == nl .or. c == ',')
  end function index_separator

  pure logical function is_letter(c)
    character(len=1), intent(in) :: c
    is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
  end function is_letter

  pure logical function is_name_char(c)
    character(len=1), intent(in) :: c
    is_name_char = is_letter(c) .or. is_digit(c) .or. c == '_'
  end function is_name_char

  !> The text without blanks (index texts such as `( 2 : 3 )`).
  function compact(t) result(r)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: r
    integer :: i
    r = ''
    do i = 1, len(t)
      if (t(i:i) /= ' ' .and. t(i:i) /= nl) r = r // t(i:i)
    end do
  end function compact

end module m_deck_parse
