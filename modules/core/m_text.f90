!> Text helpers that the whole code uses: an integer as text, a real in the shortest text
!> that reads back bit for bit (decks, XDMF), lower case, the edit distance behind "did you
!> mean" hints, a string quoted for a deck, lists written 'a, b, c', a path written one way
!> only, its last component and its folder, a text with one substring replaced by another,
!> the place of a name in a list of choices (the names a module exports for a deck
!> variable), and a whole file as one string (a deck, the resolved deck). Text in, text out.
module m_text
  use m_kinds, only: wp, i8
  use m_errors, only: fatal
  implicit none
  private
  public :: int_text, base_name, dir_name, normal_path, replaced, choice_index, file_text
  public :: to_lower, edit_distance, real_text, quoted, in_list, joined, got_text

  !> ', got <x>' for an error message (a real or an integer)
  interface got_text
    module procedure got_real, got_integer
  end interface got_text

contains

  function int_text(i) result(r)
    integer, intent(in) :: i
    character(len=:), allocatable :: r
    character(len=16) :: buf
    write(buf, '(i0)') i
    r = trim(buf)
  end function int_text

  !> The last component of a path ('decks/sod.nml' -> 'sod.nml').
  function base_name(path) result(r)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: r
    r = normal_path(path)
    if (len(r) > 1) r = r(index(r, '/', back=.true.) + 1:)
  end function base_name

  !> The folder part of a path, normalised ('./a//b/c.h5' -> 'a/b', 'c.h5' -> '.').
  function dir_name(path) result(r)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: r
    r = normal_path(path(1:index(trim(path), '/', back=.true.)))
  end function dir_name

  !> t with every old replaced by new (quoting: an inner quote doubled, or as '\'' for a shell).
  function replaced(t, old, new) result(r)
    character(len=*), intent(in) :: t, old, new
    character(len=:), allocatable :: r, rest
    integer :: k
    r = ''
    rest = t
    do while (index(rest, old) > 0)
      k = index(rest, old)
      r = r // rest(1:k - 1) // new
      rest = rest(k + len(old):)
    end do
    r = r // rest
  end function replaced

  !> A path written one way only: no '//', no '/./', no leading './', no trailing '/'.
  function normal_path(path) result(r)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: r, rest
    integer :: k
    rest = trim(adjustl(path)) // '/'
    r = repeat('/', merge(1, 0, rest(1:1) == '/' .and. len(rest) > 1))
    do while (len(rest) > 0)   ! each component but '' and '.'
      k = index(rest, '/')
      if (k > 1 .and. rest(1:k - 1) /= '.') r = r // rest(1:k - 1) // '/'
      rest = rest(k + 1:)
    end do
    if (len(r) > 1) r = r(1:len(r) - 1)
    if (len(r) == 0) r = '.'
  end function normal_path

  !> The position of name in the choice list names. A name not on the list is a programming
  !> error: the deck refuses it.
  integer function choice_index(names, name, who) result(k)
    character(len=*), intent(in) :: names(:), name, who
    k = findloc(names, adjustl(name), 1)
    if (k == 0) call fatal(who, "unknown name '" // trim(name) // "'")
  end function choice_index

  !> The whole file at path as one string ('' when it cannot be read: ios and msg say why).
  subroutine file_text(path, text, ios, msg)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: text
    integer, intent(out) :: ios
    character(len=*), intent(inout) :: msg
    integer :: u, n
    text = ''
    open(newunit=u, file=path, access='stream', form='unformatted', action='read', &
      status='old', iostat=ios, iomsg=msg)
    if (ios /= 0) return
    inquire(unit=u, size=n)
    text = repeat(' ', max(n, 0))
    if (n > 0) read(u, iostat=ios, iomsg=msg) text
    close(u)
  end subroutine file_text
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

  function got_real(x) result(t)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: t
    t = ', got ' // real_text(x)
  end function got_real

  function got_integer(i) result(t)
    integer, intent(in) :: i
    character(len=:), allocatable :: t
    t = ', got ' // int_text(i)
  end function got_integer

end module m_text
