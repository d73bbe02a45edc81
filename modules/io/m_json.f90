!> A small JSON writer for run.json (manual/user-guide.md): a json_t collects nested objects
!> and arrays of numbers, text and logicals into one string, commas and quotes handled here,
!> which json_write puts into a file. A real that is not finite becomes null (JSON has no
!> NaN). It writes only; tools read the file (tools/sabre_py/runjson.py). No MPI: the caller
!> decides which rank writes.
module m_json
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use m_kinds, only: wp, i8
  implicit none
  private
  public :: json_t, json_begin, json_end, json_object, json_close, json_put, json_put_array, &
    json_put_members, json_write

  integer, parameter :: max_depth = 8

  type :: json_t
    character(len=:), allocatable :: text
    integer :: depth = 0
    logical :: first(max_depth) = .true.   !< nothing written yet at that depth
  end type json_t

  interface json_put
    module procedure put_real, put_int, put_int8, put_text, put_logical
  end interface json_put

  interface json_put_array
    module procedure put_real_array, put_int_array, put_text_array
  end interface json_put_array

contains

  !> Start the top-level object.
  subroutine json_begin(js)
    type(json_t), intent(out) :: js
    js%text = '{'
    js%depth = 1
    js%first = .true.
  end subroutine json_begin

  !> Close the top-level object.
  subroutine json_end(js)
    type(json_t), intent(inout) :: js
    call json_close(js)
    js%text = js%text // new_line('a')
  end subroutine json_end

  !> Open the object "key": { inside the current one.
  subroutine json_object(js, key)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    call put_key(js, key)
    js%text = js%text // '{'
    js%depth = min(js%depth + 1, max_depth)
    js%first(js%depth) = .true.
  end subroutine json_object

  !> Close the innermost open object.
  subroutine json_close(js)
    type(json_t), intent(inout) :: js
    js%text = js%text // new_line('a') // repeat('  ', max(js%depth - 1, 0)) // '}'
    js%depth = max(js%depth - 1, 0)
  end subroutine json_close

  subroutine put_key(js, key)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    if (.not. js%first(js%depth)) js%text = js%text // ','
    js%first(js%depth) = .false.
    js%text = js%text // new_line('a') // repeat('  ', js%depth) // quoted(key) // ': '
  end subroutine put_key

  subroutine put_real(js, key, x)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    real(wp), intent(in) :: x
    call put_key(js, key)
    js%text = js%text // number(x)
  end subroutine put_real

  subroutine put_int(js, key, n)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    integer, intent(in) :: n
    call put_int8(js, key, int(n, i8))
  end subroutine put_int

  subroutine put_int8(js, key, n)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    integer(i8), intent(in) :: n
    character(len=24) :: buf
    call put_key(js, key)
    write(buf, '(i0)') n
    js%text = js%text // trim(buf)
  end subroutine put_int8

  subroutine put_text(js, key, text)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key, text
    call put_key(js, key)
    js%text = js%text // quoted(trim(text))
  end subroutine put_text

  subroutine put_logical(js, key, flag)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    logical, intent(in) :: flag
    call put_key(js, key)
    js%text = js%text // trim(merge('true ', 'false', flag))
  end subroutine put_logical

  subroutine put_real_array(js, key, x)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    real(wp), intent(in) :: x(:)
    integer :: k
    call put_key(js, key)
    js%text = js%text // '['
    do k = 1, size(x)
      if (k > 1) js%text = js%text // ', '
      js%text = js%text // number(x(k))
    end do
    js%text = js%text // ']'
  end subroutine put_real_array

  subroutine put_int_array(js, key, n)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key
    integer, intent(in) :: n(:)
    character(len=16) :: buf
    integer :: k
    call put_key(js, key)
    js%text = js%text // '['
    do k = 1, size(n)
      if (k > 1) js%text = js%text // ', '
      write(buf, '(i0)') n(k)
      js%text = js%text // trim(buf)
    end do
    js%text = js%text // ']'
  end subroutine put_int_array

  subroutine put_text_array(js, key, text)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: key, text(:)
    integer :: k
    call put_key(js, key)
    js%text = js%text // '['
    do k = 1, size(text)
      if (k > 1) js%text = js%text // ', '
      js%text = js%text // quoted(trim(text(k)))
    end do
    js%text = js%text // ']'
  end subroutine put_text_array

  !> Several real members given as a table: keys(k): x(k), in order (trailing blanks of a
  !> key are not part of it).
  subroutine json_put_members(js, keys, x)
    type(json_t), intent(inout) :: js
    character(len=*), intent(in) :: keys(:)
    real(wp), intent(in) :: x(:)
    integer :: k
    do k = 1, size(keys)
      call put_real(js, trim(keys(k)), x(k))
    end do
  end subroutine json_put_members

  !> Write the text to path; ok is false when the file cannot be written.
  subroutine json_write(js, path, ok)
    type(json_t), intent(in) :: js
    character(len=*), intent(in) :: path
    logical, intent(out) :: ok
    integer :: u, ios
    open(newunit=u, file=path, status='replace', access='stream', form='unformatted', &
      action='write', iostat=ios)
    ok = (ios == 0)
    if (.not. ok) return
    write(u, iostat=ios) js%text
    ok = (ios == 0)
    close(u)
  end subroutine json_write

  !> A JSON number with every digit of x, or null when x is not finite.
  function number(x) result(r)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: r
    character(len=32) :: buf
    if (.not. ieee_is_finite(x)) then
      r = 'null'
      return
    end if
    write(buf, '(es25.16e3)') x
    r = trim(adjustl(buf))
  end function number

  !> text in double quotes, with quotes, backslashes and control characters escaped
  function quoted(text) result(r)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: r
    character(len=6) :: esc
    integer :: k, c
    r = '"'
    do k = 1, len(text)
      c = iachar(text(k:k))
      if (text(k:k) == '"' .or. text(k:k) == '\') then
        r = r // '\' // text(k:k)
      else if (c < 32) then
        write(esc, '(a,z4.4)') '\u', c
        r = r // esc
      else
        r = r // text(k:k)
      end if
    end do
    r = r // '"'
  end function quoted

end module m_json
