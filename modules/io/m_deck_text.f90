!> The small text helpers of the deck modules (DESIGN section 6): lower case, the edit
!> distance behind "did you mean" hints, reals as deck text (in the shortest form that reads
!> back bit for bit), quoting for a deck and lists written 'a, b, c' (the helpers the rest
!> of the code uses too are core/m_text's). Text in, text out: it knows nothing of groups,
!> variables or the configuration, does no I/O and never stops the run.
module m_deck_text
  use m_kinds, only: wp, i8
  use m_text, only: int_text, replaced
  implicit none
  private
  public :: to_lower, edit_distance, real_text, quoted, in_list, joined

contains

  elemental function to_lower(t) result(r)
    character(len=*), intent(in) :: t
    character(len=len(t)) :: r
    integer :: i
    r = t
    do i = 1, len(t)
      if (t(i:i) >= 'A' .and. t(i:i) <= 'Z') r(i:i) = achar(iachar(t(i:i)) + 32)
    end do
  end function to_lower

  !> Edit distance (insertions, deletions, substitutions and swaps of two neighbours).
  pure integer function edit_distance(a, b) result(d)
    character(len=*), intent(in) :: a, b
    integer :: m(0:len(a), 0:len(b))
    integer :: i, j, cost
    do i = 0, len(a)
      m(i, 0) = i
    end do
    do j = 0, len(b)
      m(0, j) = j
    end do
    do j = 1, len(b)
      do i = 1, len(a)
        cost = merge(0, 1, a(i:i) == b(j:j))
        m(i, j) = min(m(i - 1, j) + 1, m(i, j - 1) + 1, m(i - 1, j - 1) + cost)
        if (i > 1 .and. j > 1) then
          if (a(i:i) == b(j - 1:j - 1) .and. a(i - 1:i - 1) == b(j:j)) &
            m(i, j) = min(m(i, j), m(max(i - 2, 0), max(j - 2, 0)) + 1)
        end if
      end do
    end do
    d = m(len(a), len(b))
  end function edit_distance

  !> The shortest decimal text that reads back as exactly x, e.g. 0.2, 101325.0, 6.0e8,
  !> 1.0e-7: deck files stay readable and the resolved deck round-trips bit for bit.
  function real_text(x) result(r)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: r
    character(len=40) :: buf
    character(len=:), allocatable :: digits
    character(len=16) :: fmt
    real(wp) :: y
    integer :: d, e_at, ex, ios
    if (.not. abs(x) > 0.0_wp) then
      r = '0.0'
      return
    end if
    do d = 1, 17
      write(fmt, '(a,i0,a)') '(es40.', d - 1, 'e3)'
      write(buf, fmt) abs(x)
      read(buf, *, iostat=ios) y
      if (ios == 0 .and. transfer(y, 0_i8) == transfer(abs(x), 0_i8)) exit
    end do
    buf = adjustl(buf)
    e_at = index(buf, 'E')
    read(buf(e_at + 1:), *) ex
    digits = buf(1:1) // buf(3:e_at - 1)   ! (without the trailing zeros)
    digits = digits(1:max(1, verify(digits, '0', back=.true.)))
    if (ex >= 0 .and. ex <= 6) then
      if (len(digits) <= ex + 1) then
        r = digits // repeat('0', ex + 1 - len(digits)) // '.0'
      else
        r = digits(1:ex + 1) // '.' // digits(ex + 2:)
      end if
    else if (ex < 0 .and. ex >= -3) then
      r = '0.' // repeat('0', -ex - 1) // digits
    else if (len(digits) == 1) then
      r = digits // '.0e' // int_text(ex)
    else
      r = digits(1:1) // '.' // digits(2:) // 'e' // int_text(ex)
    end if
    if (x < 0.0_wp) r = '-' // r
  end function real_text

  !> A string as a deck value: in single quotes, the trailing blanks dropped, an inner quote
  !> doubled.
  function quoted(t) result(r)
    character(len=*), intent(in) :: t
    character(len=:), allocatable :: r
    r = "'" // replaced(trim(t), "'", "''") // "'"
  end function quoted

  !> Whether word is one of the items of a list written 'a, b, c'.
  elemental logical function in_list(word, list)
    character(len=*), intent(in) :: word, list
    in_list = len_trim(word) > 0 .and. index(', ' // list // ',', ', ' // trim(word) // ',') > 0
  end function in_list

  !> The items of a list as one text 'a, b, c'.
  function joined(items) result(r)
    character(len=*), intent(in) :: items(:)
    character(len=:), allocatable :: r
    integer :: k
    r = trim(items(1))
    do k = 2, size(items)
      r = r // ', ' // trim(items(k))
    end do
  end function joined

end module m_deck_text
