!> The check of one value text against the variable it is meant for (DESIGN section 6):
!> index syntax and range, the number of values (r*c repeats included) and the form of each
!> constant: an integer or a real that fits, a logical, a quoted string no longer than the
!> variable. gfortran's own namelist reader accepts `3` for a string, `1` for a logical and
!> `1e999` for a real (which then traps), hence this check before every READ. It describes
!> a variable (var_info_t) but holds no table of them (m_deck_schema), and never stops the
!> run: it returns the reason a value is refused.
module m_deck_values
  use m_deck_text, only: to_lower, int_text, unquote, string_end, is_digit
  implicit none
  private
  public :: var_info_t, check_value

  !> What a deck variable is: kind 'c' (string), 'i', 'r' or 'l'; size 1 for a scalar;
  !> clen the length of a string variable; typical an example value for error messages.
  type :: var_info_t
    character(len=24) :: name = ''
    character(len=1) :: kind = 'r'
    integer :: size = 1
    integer :: clen = 0
    character(len=48) :: typical = ''
  end type var_info_t

contains

  !> Why `subscript` and `value` cannot be assigned to a variable described by info, or ''
  !> when they can: index syntax and range, number of values, and the form of each value.
  function check_value(info, subscript, value) result(why)
    type(var_info_t), intent(in) :: info
    character(len=*), intent(in) :: subscript, value
    character(len=:), allocatable :: why
    character(len=:), allocatable :: item, constant
    integer :: first, last, room, count, p, star, repeat, ios

    why = ''
    first = 1
    last = info%size
    if (len(subscript) > 0) then
      if (info%size == 1) then
        why = 'is not an array: remove ' // subscript
        return
      end if
      call parse_index(subscript, first, last, why)
      if (len(why) > 0) return
      if (first < 1 .or. last > info%size .or. first > last) then
        why = 'index ' // subscript // ' out of range 1..' // int_text(info%size)
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
        if (star > 10 .or. .not. all_digits(item(1:star - 1))) then
          why = 'bad repeat count in ' // item
          return
        end if
        read(item(1:star - 1), *, iostat=ios) repeat
        if (ios /= 0 .or. repeat < 1) then
          why = 'bad repeat count in ' // item
          return
        end if
        constant = item(star + 1:)
      end if
      count = count + repeat
      if (count > room) then
        if (room == 1) then
          why = 'takes one value, got more: ' // value
        else
          why = 'too many values (at most ' // int_text(room) // '): ' // value
        end if
        return
      end if
      if (len(constant) > 0) then
        why = check_constant(info, constant)
        if (len(why) > 0) return
      end if
    end do
    if (count == 0) why = 'no value given'
  end function check_value

  function check_constant(info, c) result(why)
    type(var_info_t), intent(in) :: info
    character(len=*), intent(in) :: c
    character(len=:), allocatable :: why
    why = ''
    select case (info%kind)
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
    case ('c')
      if (c(1:1) /= "'" .and. c(1:1) /= '"') then
        why = "expected a quoted string such as 'abc', got " // c
      else if (len(unquote(c)) > info%clen) then
        why = 'string longer than ' // int_text(info%clen) // ' characters: ' // c
      end if
    end select
  end function check_constant

  !> The next value item of a value text from position p (a constant, r*constant, r* or a
  !> null value between two commas); p = -1 when there is none left.
  subroutine next_item(value, p, item)
    character(len=*), intent(in) :: value
    integer, intent(inout) :: p
    character(len=:), allocatable, intent(out) :: item
    integer :: q, e
    item = ''
    do while (p <= len(value))
      if (value(p:p) /= ' ') exit
      p = p + 1
    end do
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
        q = e + 1
        cycle
      end if
      q = q + 1
    end do
    item = value(p:q - 1)
    p = q
    do while (p <= len(value))
      if (value(p:p) /= ' ') exit
      p = p + 1
    end do
    if (p <= len(value)) then
      if (value(p:p) == ',') p = p + 1
    end if
  end subroutine next_item

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
    integer :: i
    k = 0
    do i = 1, len(item)
      if (item(i:i) == "'" .or. item(i:i) == '"') return
      if (item(i:i) == '*') then
        k = i
        return
      end if
    end do
  end function index_of_star

  pure logical function all_digits(t)
    character(len=*), intent(in) :: t
    integer :: i
    all_digits = len(t) > 0
    do i = 1, len(t)
      if (.not. is_digit(t(i:i))) all_digits = .false.
    end do
  end function all_digits

  pure logical function integer_form(t)
    character(len=*), intent(in) :: t
    integer :: s0
    s0 = 1
    if (len(t) > 0) then
      if (t(1:1) == '+' .or. t(1:1) == '-') s0 = 2
    end if
    integer_form = all_digits(t(s0:))
  end function integer_form

  logical function integer_fits(t)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: d
    integer :: s0
    s0 = 1
    if (t(1:1) == '+' .or. t(1:1) == '-') s0 = 2
    d = t(s0:)
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
    i = 1
    if (len(t) == 0) return
    if (t(1:1) == '+' .or. t(1:1) == '-') i = 2
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
    if (i > len(t)) then
      real_form = .true.
      return
    end if
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
      if (len(t) - e_at > 6) then
        real_fits = .false.
        return
      end if
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
        else if (nonzero .and. .not. seen_dot) then
          lead = lead + 1
        else if (.not. nonzero .and. seen_dot) then
          lead = lead - 1
        end if
      end if
    end do
    real_fits = .not. nonzero .or. abs(lead + exponent) < 300
  end function real_fits

end module m_deck_values
