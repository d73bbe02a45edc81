!> Text helpers that the whole code uses: an integer as text, a path written one way only,
!> its last component and its folder, a text with one substring replaced by another, the place of a name in a list of choices (the names a module
!> exports for a deck variable), and a whole file as one string (a deck, the resolved deck).
module m_text
  use m_errors, only: fatal
  implicit none
  private
  public :: int_text, base_name, dir_name, normal_path, replaced, choice_index, file_text

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

end module m_text
