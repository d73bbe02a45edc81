!> One deck variable and its value texts (DESIGN section 6): deck_var_t describes a variable
!> of m_deck_schema's table and points at the configuration component it stands for;
!> check_value says why a value text cannot be assigned to it (index syntax and range, the
!> number of values, r*c repeats included, the form of each constant: an integer or a real
!> that fits, a logical, a quoted string no longer than the variable; gfortran's own reader
!> accepts `3` for a string, `1` for a logical and `1e999` for a real, which then traps);
!> read_value reads a checked text into the component, value_text writes the component back
!> as deck text. It holds no table (m_deck_schema) and never stops the run.
module m_deck_values
  use m_kinds, only: wp, name_len
  use m_config, only: is_set
  use m_deck_text, only: to_lower, int_text, real_text, quoted, unquote, string_end, is_digit
  implicit none
  private
  public :: deck_var_t, check_value, read_value, value_text

  !> group and name; kind 'r' real, 'i' integer, 'l' logical, 'c' string or 'k' keyword (a
  !> string lower-cased when read, one of `choices`, or empty when `empty_ok`); size (1 for
  !> a scalar), the length of a string, a typical value for the messages, the meaning; the
  !> component read and written (one pointer associated, by type and rank) and, for a list
  !> that is written only as far as it is used, the count of its entries.
  type :: deck_var_t
    character(len=8) :: group = ''
    character(len=24) :: name = ''
    character(len=1) :: kind = 'r'
    integer :: size = 1, clen = 0
    character(len=48) :: typical = ''
    character(len=:), allocatable :: choices, meaning
    logical :: empty_ok = .false.
    real(wp), pointer :: r => null(), ra(:) => null()
    integer, pointer :: i => null(), ia(:) => null()
    logical, pointer :: l => null()
    character(len=:), pointer :: c => null()
    character(len=name_len), pointer :: ca(:) => null()
    integer, pointer :: count => null()
  end type deck_var_t

contains

  !> Why `subscript` and `value` cannot be assigned to v, or '' when they can.
  function check_value(v, subscript, value) result(why)
    type(deck_var_t), intent(in) :: v
    character(len=*), intent(in) :: subscript, value
    character(len=:), allocatable :: why, item, constant
    integer :: first, last, room, count, p, star, repeat, ios
    why = ''
    first = 1
    last = v%size
    if (len(subscript) > 0) then
      if (v%size == 1) then
        why = 'is not an array: remove ' // subscript
        return
      end if
      call parse_index(subscript, first, last, why)
      if (len(why) > 0) return
      if (first < 1 .or. last > v%size .or. first > last) then
        why = 'index ' // subscript // ' out of range 1..' // int_text(v%size)
        return
      end if
    end if
    room = last - first + 1
    count = 0
    p = 1
    do
      call next_item(value, p, item)
      if (p < 0) exit
      repeat = 1
      constant = item
      star = index_of_star(item)
      if (star > 0) then
        ios = 1
        if (star <= 10 .and. all_digits(item(1:star - 1))) &
          read(item(1:star - 1), *, iostat=ios) repeat
        if (ios /= 0 .or. repeat < 1) why = 'bad repeat count in ' // item
        if (len(why) > 0) return
        constant = item(star + 1:)
      end if
      count = count + repeat
      if (count > room .and. room == 1) why = 'takes one value, got more: ' // value
      if (count > room .and. room > 1) why = 'too many values (at most ' // int_text(room) &
        // '): ' // value
      if (len(constant) > 0 .and. len(why) == 0) why = check_constant(v, constant)
      if (len(why) > 0) return
    end do
    if (count == 0) why = 'no value given'
  end function check_value

  function check_constant(v, c) result(why)
    type(deck_var_t), intent(in) :: v
    character(len=*), intent(in) :: c
    character(len=:), allocatable :: why
    why = ''
    select case (v%kind)
    case ('i')
      if (.not. integer_form(c)) then
        why = 'expected an integer, got ' // c
      else if (.not. integer_fits(c)) then
        why = 'integer too large: ' // c
      end if
    case ('r')
      if (.not. real_form(c)) then
        why = 'expected a real number, got ' // c
      else if (.not. real_fits(c)) then
        why = 'real number out of range (|x| between 1e-300 and 1e300, or 0): ' // c
      end if
    case ('l')
      select case (to_lower(c))
      case ('.true.', '.false.', 't', 'f', 'true', 'false', '.t.', '.f.')
      case default
        why = 'expected .true. or .false., got ' // c
      end select
    case default
      if (c(1:1) /= "'" .and. c(1:1) /= '"') then
        why = "expected a quoted string such as 'abc', got " // c
      else if (len(unquote(c)) > v%clen) then
        why = 'string longer than ' // int_text(v%clen) // ' characters: ' // c
      end if
    end select
  end function check_constant

  !> Read a value text that check_value has passed into the elements `subscript` of v's
  !> component (list-directed, as a namelist would: r*c repeats, null values keep what is
  !> there, and so do the elements after the last value); keywords are lower-cased.
  subroutine read_value(v, subscript, value, ios, msg)
    type(deck_var_t), intent(in) :: v
    character(len=*), intent(in) :: subscript, value
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    character(len=:), allocatable :: t, why
    integer :: lo, hi
    lo = 1
    hi = v%size
    if (len(subscript) > 0) call parse_index(subscript, lo, hi, why)
    t = value // ' /'
    ios = 0
    if (associated(v%r)) read(t, *, iostat=ios, iomsg=msg) v%r
    if (associated(v%ra)) read(t, *, iostat=ios, iomsg=msg) v%ra(lo:hi)
    if (associated(v%i)) read(t, *, iostat=ios, iomsg=msg) v%i
    if (associated(v%ia)) read(t, *, iostat=ios, iomsg=msg) v%ia(lo:hi)
    if (associated(v%l)) read(t, *, iostat=ios, iomsg=msg) v%l
    if (associated(v%c)) read(t, *, iostat=ios, iomsg=msg) v%c
    if (associated(v%ca)) read(t, *, iostat=ios, iomsg=msg) v%ca(lo:hi)
    if (v%kind /= 'k') return
    if (associated(v%c)) v%c = to_lower(v%c)
    if (associated(v%ca)) v%ca = to_lower(v%ca)
  end subroutine read_value

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

  !> The next value item of a value text from position p (a constant, r*constant, r* or a
  !> null value between two commas); p = -1 when there is none left.
  subroutine next_item(value, p, item)
    character(len=*), intent(in) :: value
    integer, intent(inout) :: p
    character(len=:), allocatable, intent(out) :: item
    integer :: q, e
    item = ''
    p = skip_blanks(value, p)
    if (p > len(value)) then
      p = -1
      return
    end if
    if (value(p:p) == ',') then
      p = p + 1
      return
    end if
    q = p
    do while (q <= len(value))
      if (value(q:q) == ' ' .or. value(q:q) == ',') exit
      if (value(q:q) == "'" .or. value(q:q) == '"') then
        e = string_end(value, q)
        if (e == 0) e = len(value)
        q = e
      end if
      q = q + 1
    end do
    item = value(p:q - 1)
    p = skip_blanks(value, q)
    if (p <= len(value)) then
      if (value(p:p) == ',') p = p + 1
    end if
  end subroutine next_item

  pure integer function skip_blanks(t, p) result(q)
    character(len=*), intent(in) :: t
    integer, intent(in) :: p
    q = p
    do while (q <= len(t))
      if (t(q:q) /= ' ') exit
      q = q + 1
    end do
  end function skip_blanks

  subroutine parse_index(subscript, first, last, why)
    character(len=*), intent(in) :: subscript
    integer, intent(out) :: first, last
    character(len=:), allocatable, intent(inout) :: why
    character(len=:), allocatable :: inner
    integer :: colon, ios1, ios2
    first = 0
    last = 0
    inner = subscript(2:len(subscript) - 1)
    colon = scan(inner, ':')
    ios1 = 1
    ios2 = 1
    if (colon == 0) then
      if (integer_form(inner) .and. len(inner) < 9) read(inner, *, iostat=ios1) first
      last = first
      ios2 = ios1
    else
      if (integer_form(inner(1:colon - 1)) .and. colon < 10) &
        read(inner(1:colon - 1), *, iostat=ios1) first
      if (integer_form(inner(colon + 1:)) .and. len(inner) - colon < 9) &
        read(inner(colon + 1:), *, iostat=ios2) last
    end if
    if (ios1 /= 0 .or. ios2 /= 0) why = 'bad index ' // subscript // ' (expected (i) or (i:j))'
  end subroutine parse_index

  integer function index_of_star(item) result(k)
    character(len=*), intent(in) :: item
    k = scan(item, '*''"')
    if (k > 0) then
      if (item(k:k) /= '*') k = 0
    end if
  end function index_of_star

  pure logical function all_digits(t)
    character(len=*), intent(in) :: t
    all_digits = len(t) > 0 .and. verify(t, '0123456789') == 0
  end function all_digits

  pure logical function integer_form(t)
    character(len=*), intent(in) :: t
    integer :: s0
    s0 = 1
    if (len(t) > 0) s0 = merge(2, 1, t(1:1) == '+' .or. t(1:1) == '-')
    integer_form = all_digits(t(s0:))
  end function integer_form

  logical function integer_fits(t)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: d
    d = t(merge(2, 1, t(1:1) == '+' .or. t(1:1) == '-'):)
    do while (len(d) > 1)
      if (d(1:1) /= '0') exit
      d = d(2:)
    end do
    integer_fits = len(d) < 10 .or. (len(d) == 10 .and. d <= '2147483647')
  end function integer_fits

  !> [sign] digits [. [digits]] | [sign] . digits, then optionally e|d [sign] digits.
  pure logical function real_form(t)
    character(len=*), intent(in) :: t
    integer :: i, n_digits, n_dots
    real_form = .false.
    if (len(t) == 0) return
    i = merge(2, 1, t(1:1) == '+' .or. t(1:1) == '-')
    n_digits = 0
    n_dots = 0
    do while (i <= len(t))
      if (is_digit(t(i:i))) then
        n_digits = n_digits + 1
      else if (t(i:i) == '.') then
        n_dots = n_dots + 1
      else
        exit
      end if
      i = i + 1
    end do
    if (n_digits == 0 .or. n_dots > 1) return
    real_form = i > len(t)
    if (real_form) return
    if (index('eEdD', t(i:i)) == 0) return
    i = i + 1
    if (i <= len(t)) then
      if (t(i:i) == '+' .or. t(i:i) == '-') i = i + 1
    end if
    real_form = all_digits(t(i:))
  end function real_form

  !> Whether a number of real_form lies in the safe range: 0, or 1e-300 < |x| < 1e300
  !> (reading 1e999 would trap with -ffpe-trap=overflow).
  logical function real_fits(t)
    character(len=*), intent(in) :: t
    integer :: i, e_at, exponent, lead, ios
    logical :: seen_dot, nonzero
    e_at = scan(t, 'eEdD')
    exponent = 0
    if (e_at > 0) then
      real_fits = .false.
      if (len(t) - e_at > 6) return
      read(t(e_at + 1:), *, iostat=ios) exponent
    else
      e_at = len(t) + 1
    end if
    ! lead: the power of ten of the first non-zero digit of the mantissa
    lead = 0
    seen_dot = .false.
    nonzero = .false.
    do i = 1, e_at - 1
      if (t(i:i) == '.') then
        seen_dot = .true.
      else if (is_digit(t(i:i))) then
        if (.not. nonzero .and. t(i:i) /= '0') then
          nonzero = .true.
          if (seen_dot) lead = lead - 1
        else if (nonzero .neqv. seen_dot) then
          lead = lead + merge(1, -1, nonzero)
        end if
      end if
    end do
    real_fits = .not. nonzero .or. abs(lead + exponent) < 300
  end function real_fits

end module m_deck_values
