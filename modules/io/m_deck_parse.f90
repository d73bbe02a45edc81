!> The lexical layer of deck reading (DESIGN section 6), by hand rather than by a namelist
!> READ so that every complaint can name the group, the variable and the line: deck_split
!> makes groups of assignments `name[(index)] = value-text`; assign_value checks a value
!> for a table line (deck_var_t) and reads it list-directed, as a namelist would, after
!> checking each constant's form (gfortran's reader takes `3` for a string, `1` for a
!> logical, and traps on `1e999`); value_text writes it back. It returns reasons, never stops.
module m_deck_parse
  use, intrinsic :: iso_fortran_env, only: int64
  use m_kinds, only: wp, name_len, line_len
  use m_config, only: is_set
  use m_text, only: int_text, to_lower, real_text, quoted, replaced
  implicit none
  private
  public :: deck_var_t, deck_group_t, deck_assign_t
  public :: deck_split, first_group, assign_value, value_text

  !> One table line (m_deck_schema's deck_table): kind 'r' real, 'i' integer, 'l' logical,
  !> 'c' string or 'k' keyword (lower-cased, one of `choices`, or empty when `empty_ok`);
  !> the component as the one pointer associated, and for a list written only as far as it
  !> is used, the count of its entries.
  type :: deck_var_t
    character(len=8) :: group = ''
    character(len=24) :: name = ''
    character(len=1) :: kind = 'r'
    integer :: size = 1, clen = 0
    character(len=48) :: typical = ''
    character(len=64) :: allowed = ''
    character(len=:), allocatable :: choices, meaning
    logical :: empty_ok = .false.
    real(wp), pointer :: r => null(), ra(:) => null()
    integer, pointer :: i => null(), ia(:) => null()
    logical, pointer :: l => null()
    character(len=:), pointer :: c => null()
    character(len=name_len), pointer :: ca(:) => null()
    integer, pointer :: count => null()
  end type deck_var_t

  !> One `&name ... /` group in deck order; line 0: made for a command-line override.
  type :: deck_group_t
    character(len=:), allocatable :: name   !< lower case
    integer :: line = 0
  end type deck_group_t

  !> One `name[(index)] = value` of group `group` (its place in the groups); line 0: it
  !> came from the command line. The index keeps its parentheses, the value its spacing.
  type :: deck_assign_t
    integer :: group = 0, line = 0
    character(len=:), allocatable :: name, index, value
  end type deck_assign_t

  !> kind: '&', '/', ',', '=', '(' a subscript, 'w' a word (a name, a constant, r*c, a
  !> quoted string), '?' a string not closed on its line; first, last: where in the text
  type :: token_t
    character(len=1) :: kind = 'w'
    integer :: line = 1, first = 1, last = 0
  end type token_t

  character(len=1), parameter :: nl = achar(10)

contains

  !> The tokens of s; comments are blanked in s on the way.
  subroutine tokenize(s, tok)
    character(len=*), intent(inout) :: s
    type(token_t), allocatable, intent(out) :: tok(:)
    integer :: p, q, e, line
    logical :: bad
    allocate(tok(0))
    p = 1
    line = 1
    do while (p <= len(s))
      q = p
      select case (s(p:p))
      case (nl)
        line = line + 1
      case ('!')
        q = p + index(s(p:) // nl, nl) - 2
        s(p:q) = ' '
      case ('&', '/', ',', '=')
        tok = [tok, token_t(s(p:p), line, p, p)]
      case ('(')
        e = scan(s(p:), ')=' // nl)
        if (e > 0 .and. index(s(p:), ')') == e) q = p + e - 1
        tok = [tok, token_t(merge('(', 'w', q > p), line, p, q)]
      case (' ')
      case default   ! a word, the strings in it taken whole
        bad = .false.
        do while (q <= len(s) .and. .not. bad)
          if (index(' ,/&=!(' // nl, s(q:q)) > 0) exit
          if (s(q:q) == "'" .or. s(q:q) == '"') then
            e = string_end(s, q)
            bad = (e == 0)
            q = merge(q - 2 + index(s(q:) // nl, nl), e, bad)   ! unclosed: the rest of the line
          end if
          q = q + 1
        end do
        tok = [tok, token_t(merge('?', 'w', bad), line, p, q - 1)]
        q = q - 1
      end select
      p = q + 1
    end do
  end subroutine tokenize

  !> Position of the quote closing the string that opens at p, or 0 if the line ends first
  !> (a doubled quote inside stands for one quote character).
  integer function string_end(s, p) result(e)
    character(len=*), intent(in) :: s
    integer, intent(in) :: p
    e = p + 1
    do while (e <= len(s))
      if (s(e:e) == nl) exit
      if (s(e:e) == s(p:p)) then
        if (s(e:min(e + 1, len(s))) /= s(p:p) // s(p:p)) return
        e = e + 1
      end if
      e = e + 1
    end do
    e = 0
  end function string_end

  !> Split deck text into groups and their assignments. On a syntax error, err_what says
  !> what and where (the offending line echoed), err_group names the group it is in ('' if
  !> none), and what was found before it is returned.
  subroutine deck_split(text, groups, assigns, err_group, err_what)
    character(len=*), intent(in) :: text
    type(deck_group_t), allocatable, intent(out) :: groups(:)
    type(deck_assign_t), allocatable, intent(out) :: assigns(:)
    character(len=:), allocatable, intent(out) :: err_group, err_what
    character(len=:), allocatable :: s, name, subscript
    type(token_t), allocatable :: t(:)
    integer :: k, n, v0, nk, last
    allocate(groups(0), assigns(0))
    err_group = ''
    err_what = ''
    s = replaced(replaced(text, achar(9), ' '), achar(13), ' ')
    call tokenize(s, t)
    s = replaced(s, nl, ' ')
    n = size(t)
    t = [t, token_t('&', 0, len(s) + 1, len(s))]   ! a guard: the end of the text
    k = 1
    do while (k <= n)
      if (t(k)%kind /= '&') then
        call syntax(k, 'text outside a group; a group starts with &name and ends with /')
        return
      else if (t(k + 1)%kind /= 'w' .or. t(k + 1)%first /= t(k)%last + 1) then
        call syntax(k, "'&' without a group name")
        return
      end if
      err_group = to_lower(word(k + 1))
      groups = [groups, deck_group_t(err_group, t(k)%line)]
      v0 = 0   ! the first token of the value being read (0: none yet), nk its name's
      do k = k + 2, n + 1
        if (t(k)%kind == '&') then
          name = 'the end of the file'
          if (k <= n) name = 'line ' // int_text(t(k)%line)
          associate(line => groups(size(groups))%line)
            err_what = 'syntax error: the group opened at line ' // int_text(line) &
              // " is not closed with '/' before " // name // ': ' // line_text(line)
          end associate
          return
        else if (t(k)%kind == '/' .or. assign_length(k) > 0) then
          if (v0 > 0) then   ! the value before ends here (a trailing comma only separates)
            last = k - 1
            do while (last >= v0 .and. t(last)%kind == ',')
              last = last - 1
            end do
            if (last < v0) then
              call syntax(nk, "no value after '='; give a value or remove the line")
              return
            end if
            name = to_lower(word(nk))
            subscript = replaced(word(nk + 1), ' ', '')
            if (assign_length(nk) == 2) subscript = ''
            assigns = [assigns, deck_assign_t(size(groups), t(nk)%line, name, subscript, &
              s(t(v0)%first:t(last)%last))]
          end if
          if (t(k)%kind == '/') exit
          nk = k
          v0 = k + assign_length(k)
        else if (v0 == 0) then
          call syntax(k, 'expected name = value')
          return
        else if (t(k)%kind == '?') then
          call syntax(k, 'unterminated string')
          return
        end if
      end do
      k = k + 1
      err_group = ''
    end do

  contains

    function word(k) result(w)
      integer, intent(in) :: k
      character(len=:), allocatable :: w
      w = s(t(k)%first:t(k)%last)
    end function word

    !> 2 for `name =`, 3 for `name (index) =` at token k, else 0
    integer function assign_length(k) result(m)
      integer, intent(in) :: k
      m = 0
      if (t(k)%kind /= 'w' .or. .not. is_name(word(k))) return
      if (t(k + 1)%kind == '=') m = 2
      if (t(k + 1)%kind == '(' .and. t(min(k + 2, n + 1))%kind == '=') m = 3
    end function assign_length

    !> line `line` of the text, fit to be echoed in a one-line message
    function line_text(line) result(r)
      integer, intent(in) :: line
      character(len=:), allocatable :: r
      integer :: k
      r = text
      do k = 2, line
        r = r(index(r, nl) + 1:)
      end do
      r = trim(adjustl(r(1:index(r // nl, nl) - 1)))
      do k = 1, len(r)
        if (iachar(r(k:k)) < 32 .or. iachar(r(k:k)) > 126) r(k:k) = '?'
      end do
      if (len(r) > 120) r = r(1:117) // '...'
    end function line_text

    subroutine syntax(k, what)
      integer, intent(in) :: k
      character(len=*), intent(in) :: what
      err_what = 'syntax error at line ' // int_text(t(k)%line) // ' (' // what // '): ' &
        // line_text(t(k)%line)
    end subroutine syntax

  end subroutine deck_split

  !> The place of the first group called name in groups, 0 when there is none.
  pure integer function first_group(groups, name) result(k)
    type(deck_group_t), intent(in) :: groups(:)
    character(len=*), intent(in) :: name
    do k = 1, size(groups)
      if (groups(k)%name == name) return
    end do
    k = 0
  end function first_group

  pure logical function is_name(w)
    character(len=*), intent(in) :: w
    is_name = verify(w(1:1), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ') == 0 &
      .and. verify(w, 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_') == 0
  end function is_name

  !> Assign `value` to the elements `subscript` of v's component, or say why it cannot be
  !> ('' when it was). The whole text is checked before anything is read; then it is read
  !> list-directed, as a namelist would (r*c repeats; null values keep what is there, and
  !> so do the elements after the last value); keywords are lower-cased.
  function assign_value(v, subscript, value) result(why)
    type(deck_var_t), intent(in) :: v
    character(len=*), intent(in) :: subscript, value
    character(len=:), allocatable :: why, s, item
    character(len=line_len) :: msg
    type(token_t), allocatable :: t(:)
    integer :: first, last, count, k, star, repeat, ios
    why = ''
    first = 1
    last = v%size
    if (len(subscript) > 0 .and. v%size == 1) why = 'is not an array: remove ' // subscript
    if (len(subscript) > 0 .and. v%size > 1) call parse_index(subscript, first, last, why)
    if (len(why) == 0 .and. (first < 1 .or. last > v%size .or. first > last)) &
      why = 'index ' // subscript // ' out of range 1..' // int_text(v%size)
    s = value
    call tokenize(s, t)
    count = 0
    do k = 1, size(t)
      if (len(why) > 0) return
      ! a comma after a value separates; any other stands for a null value
      if (t(k)%kind == ',' .and. k > 1) then
        if (t(k - 1)%kind /= ',') cycle
      end if
      item = s(t(k)%first:t(k)%last)
      repeat = 1
      star = scan(item, '*''"')
      if (star > 0) star = star * merge(1, 0, item(star:star) == '*')
      if (star > 0) then
        ios = 1
        if (star <= 10 .and. integer_form('+' // item(1:star - 1))) &
          read(item(1:star - 1), *, iostat=ios) repeat
        if (ios /= 0 .or. repeat < 1) why = 'bad repeat count in ' // item
        item = item(star + 1:)
      end if
      count = count + repeat
      if (len(why) > 0) cycle
      if (count > last - first + 1) then
        why = 'too many values (at most ' // int_text(last - first + 1) // '): ' // value
        if (last == first) why = 'takes one value, got more: ' // value
      else if (len(item) > 0 .and. t(k)%kind /= ',') then
        why = check_constant(v, item)
      end if
    end do
    if (count == 0 .and. len(why) == 0) why = 'no value given'
    if (len(why) > 0) return
    s = value // ' /'
    ios = 0
    msg = ''
    if (associated(v%r)) read(s, *, iostat=ios, iomsg=msg) v%r
    if (associated(v%ra)) read(s, *, iostat=ios, iomsg=msg) v%ra(first:last)
    if (associated(v%i)) read(s, *, iostat=ios, iomsg=msg) v%i
    if (associated(v%ia)) read(s, *, iostat=ios, iomsg=msg) v%ia(first:last)
    if (associated(v%l)) read(s, *, iostat=ios, iomsg=msg) v%l
    if (associated(v%c)) read(s, *, iostat=ios, iomsg=msg) v%c
    if (associated(v%ca)) read(s, *, iostat=ios, iomsg=msg) v%ca(first:last)
    if (ios /= 0) why = 'cannot read ' // value // ' (' // trim(msg) // ')'
    if (v%kind /= 'k') return
    if (associated(v%c)) v%c = to_lower(v%c)
    if (associated(v%ca)) v%ca = to_lower(v%ca)
  end function assign_value

  function check_constant(v, c) result(why)
    type(deck_var_t), intent(in) :: v
    character(len=*), intent(in) :: c
    character(len=:), allocatable :: why
    integer :: k
    integer(int64) :: big
    why = ''
    select case (v%kind)
    case ('i')
      big = huge(big)   ! (kept by a read that overflows even 64 bits)
      if (integer_form(c)) read(c, *, iostat=k) big
      if (.not. integer_form(c)) why = 'expected an integer, got ' // c
      if (len(why) == 0 .and. abs(big) > huge(1)) why = 'integer too large: ' // c
    case ('r')
      why = real_problem(c)
    case ('l')
      if (.not. any(to_lower(c) == [character(len=7) :: '.true.', '.false.', 't', 'f', &
        'true', 'false', '.t.', '.f.'])) why = 'expected .true. or .false., got ' // c
    case default
      if (c(1:1) /= "'" .and. c(1:1) /= '"') then
        why = "expected a quoted string such as 'abc', got " // c
      else if (len(c) - 2 - count([(c(k:k) == c(1:1), k = 2, len(c) - 1)]) / 2 > v%clen) then
        why = 'string longer than ' // int_text(v%clen) // ' characters: ' // c
      end if
    end select
  end function check_constant

  !> v's component as deck text ('' for a real left unset); a list with a count is written
  !> as far as it is used (one entry at least).
  function value_text(v) result(t)
    type(deck_var_t), intent(in) :: v
    character(len=:), allocatable :: t
    integer :: k, n
    t = ''
    if (associated(v%r)) then
      if (is_set(v%r)) t = real_text(v%r)
    end if
    if (associated(v%i)) t = int_text(v%i)
    if (associated(v%l)) t = trim(merge('.true. ', '.false.', v%l))
    if (associated(v%c)) t = quoted(v%c)
    n = v%size
    if (associated(v%count)) n = max(v%count, 1)
    do k = 1, n
      if (k > 1) t = t // ', '
      if (associated(v%ra)) t = t // real_text(v%ra(k))
      if (associated(v%ia)) t = t // int_text(v%ia(k))
      if (associated(v%ca)) t = t // quoted(v%ca(k))
    end do
  end function value_text

  !> `(i)` or `(i:j)` as first and last (why says what is wrong otherwise).
  subroutine parse_index(subscript, first, last, why)
    character(len=*), intent(in) :: subscript
    integer, intent(out) :: first, last
    character(len=:), allocatable, intent(inout) :: why
    character(len=:), allocatable :: inner, lo, hi
    integer :: colon
    inner = subscript(2:len(subscript) - 1)
    colon = index(inner, ':')
    lo = inner(1:merge(colon - 1, len(inner), colon > 0))
    hi = inner(colon + 1:)
    first = 0
    last = 0
    if (integer_form(lo) .and. integer_form(hi) .and. len(lo) < 9 .and. len(hi) < 9) then
      read(lo, *) first
      read(hi, *) last
    else
      why = 'bad index ' // subscript // ' (expected (i) or (i:j))'
    end if
  end subroutine parse_index

  !> [sign] digits
  pure logical function integer_form(t)
    character(len=*), intent(in) :: t
    integer :: s0
    s0 = 1
    if (len(t) > 0) s0 = merge(2, 1, t(1:1) == '+' .or. t(1:1) == '-')
    integer_form = len(t) >= s0 .and. verify(t(s0:), '0123456789') == 0
  end function integer_form

  !> Why t is not a real constant of the safe range, or '': [sign] mantissa (digits with one
  !> '.' at most) [e|d [sign] digits], 0 or 1e-300 < |x| < 1e300 (reading 1e999 would trap
  !> with -ffpe-trap=overflow).
  function real_problem(t) result(why)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: why, m, d
    integer :: e, exponent, dot
    logical :: long   ! an exponent of more than 6 characters
    why = 'expected a real number, got ' // t
    m = t(merge(2, 1, t(1:1) == '+' .or. t(1:1) == '-'):)
    e = scan(m, 'eEdD')
    exponent = 0
    long = e > 0 .and. len(m) - e > 6
    if (e > 0) then
      if (.not. integer_form(m(e + 1:))) return
      if (.not. long) read(m(e + 1:), *) exponent
      m = m(1:e - 1)
    end if
    dot = index(m // '.', '.')
    d = m(1:dot - 1) // m(dot + 1:)   ! the digits
    if (len(d) == 0 .or. verify(d, '0123456789') > 0) return
    why = ''
    ! the power of ten of the first non-zero digit
    if (verify(d, '0') > 0) long = long .or. abs(dot - 1 - verify(d, '0') + exponent) >= 300
    if (long) why = 'real number out of range (|x| between 1e-300 and 1e300, or 0): ' // t
  end function real_problem

end module m_deck_parse
