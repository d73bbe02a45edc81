!> Attributes of the root group of a SABRE HDF5 file (part of the HDF5 layer, used through
!> m_hdf5_io): reals, integers, their vectors and strings. Writers are collective and
!> store rank 0's value; an existing attribute of the same name is replaced. A scalar is
!> stored as a scalar attribute, a vector as a 1D one. Readers run on every rank and check
!> that the attribute holds as many values as asked for.
module m_hdf5_attr
  use hdf5, only: hid_t, hsize_t, h5screate_f, h5screate_simple_f, h5sclose_f, &
    h5sget_simple_extent_npoints_f, H5S_SCALAR_F, h5acreate_f, h5aopen_f, h5aclose_f, &
    h5awrite_f, h5aread_f, h5aexists_f, h5adelete_f, h5aget_space_f, h5aget_type_f, &
    h5tclose_f, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_IEEE_F64LE, H5T_STD_I32LE
  use m_kinds, only: wp
  use m_comm, only: comm_bcast
  use m_errors, only: fatal
  use m_hdf5_file, only: h5_file_t, here, require_open, string_type, string_size, &
    unpadded_len, int_text
  implicit none
  private
  public :: h5_write_attr, h5_read_attr

  interface h5_write_attr
    module procedure write_attr_real, write_attr_int, write_attr_real_array, &
      write_attr_int_array, write_attr_string
  end interface h5_write_attr

  interface h5_read_attr
    module procedure read_attr_real, read_attr_int, read_attr_real_array, &
      read_attr_int_array, read_attr_string
  end interface h5_read_attr

contains

  subroutine write_attr_real(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    call put_attr(f, name, 0, reals=[value])
  end subroutine write_attr_real

  subroutine write_attr_int(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    call put_attr(f, name, 0, ints=[value])
  end subroutine write_attr_int

  subroutine write_attr_real_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value(:)
    call put_attr(f, name, size(value), reals=value)
  end subroutine write_attr_real_array

  subroutine write_attr_int_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: value(:)
    call put_attr(f, name, size(value), ints=value)
  end subroutine write_attr_int_array

  !> Trailing blanks are not stored.
  subroutine write_attr_string(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name, value
    character(len=:), allocatable :: v
    integer(hid_t) :: attr, stype
    integer :: err
    v = trim(value)
    call comm_bcast(v, 0)
    if (len(v) == 0) v = achar(0)
    stype = string_type(len(v))
    attr = create_attr(f, name, stype, 0)
    call h5awrite_f(attr, stype, v, [1_hsize_t], err)
    call h5tclose_f(stype, err)
    call close_attr(f, name, attr, err, .true.)
  end subroutine write_attr_string

  subroutine read_attr_real(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: value
    real(wp) :: v(1)
    call get_attr(f, name, reals=v)
    value = v(1)
  end subroutine read_attr_real

  subroutine read_attr_int(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    integer :: v(1)
    call get_attr(f, name, ints=v)
    value = v(1)
  end subroutine read_attr_int

  subroutine read_attr_real_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: value(:)
    call get_attr(f, name, reals=value)
  end subroutine read_attr_real_array

  subroutine read_attr_int_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(out) :: value(:)
    call get_attr(f, name, ints=value)
  end subroutine read_attr_int_array

  !> The stored string, blank-padded to len(value); fatal when it does not fit.
  subroutine read_attr_string(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    character(len=*), intent(out) :: value
    character(len=:), allocatable :: buf
    integer(hid_t) :: attr, ftype, stype
    integer :: err, n
    attr = open_attr(f, name, 1)
    call h5aget_type_f(attr, ftype, err)
    n = string_size(ftype, 'attribute ' // name, f)
    call h5tclose_f(ftype, err)
    stype = string_type(n)
    allocate(character(len=n) :: buf)
    call h5aread_f(attr, stype, buf, [1_hsize_t], err)
    call h5tclose_f(stype, err)
    call close_attr(f, name, attr, err, .false.)
    n = unpadded_len(buf)
    if (len_trim(buf(1:n)) > len(value)) call fatal(here, 'attribute ' // name // ' of ' // &
      f%path // ' has ' // int_text(len_trim(buf(1:n))) // ' characters, more than the ' // &
      int_text(len(value)) // ' of the variable it is read into: lengthen that variable')
    value = buf(1:n)
  end subroutine read_attr_string

  ! ---------------------------------------------------------------------------------------
  ! The one writer and reader of numbers, and the attribute's life
  ! ---------------------------------------------------------------------------------------

  !> Write the reals or the integers (one of them present) as attribute name, rank 0's
  !> values; n = 0 writes a scalar attribute, else a vector of n.
  subroutine put_attr(f, name, n, reals, ints)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: n
    real(wp), intent(in), optional :: reals(:)
    integer, intent(in), optional :: ints(:)
    real(wp), allocatable :: r(:)
    integer, allocatable :: v(:)
    integer(hid_t) :: attr
    integer :: err, i
    if (present(reals)) then
      r = reals
      do i = 1, size(r)
        call comm_bcast(r(i), 0)
      end do
      attr = create_attr(f, name, H5T_IEEE_F64LE, n)
      call h5awrite_f(attr, H5T_NATIVE_DOUBLE, r, [int(size(r), hsize_t)], err)
    else
      v = ints
      call comm_bcast(v, 0)
      attr = create_attr(f, name, H5T_STD_I32LE, n)
      call h5awrite_f(attr, H5T_NATIVE_INTEGER, v, [int(size(v), hsize_t)], err)
    end if
    call close_attr(f, name, attr, err, .true.)
  end subroutine put_attr

  !> Read attribute name into the reals or the integers (one of them present), as many
  !> values as they hold.
  subroutine get_attr(f, name, reals, ints)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(out), optional :: reals(:)
    integer, intent(out), optional :: ints(:)
    integer(hid_t) :: attr
    integer :: err
    if (present(reals)) then
      attr = open_attr(f, name, size(reals))
      call h5aread_f(attr, H5T_NATIVE_DOUBLE, reals, [int(size(reals), hsize_t)], err)
    else
      attr = open_attr(f, name, size(ints))
      call h5aread_f(attr, H5T_NATIVE_INTEGER, ints, [int(size(ints), hsize_t)], err)
    end if
    call close_attr(f, name, attr, err, .false.)
  end subroutine get_attr

  !> Create a root attribute of type ftype: scalar when n = 0, else a vector of n.
  integer(hid_t) function create_attr(f, name, ftype, n) result(attr)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: ftype
    integer, intent(in) :: n
    integer(hid_t) :: space
    integer :: err
    logical :: found
    call require_open(f, 'h5_write_attr')
    call h5aexists_f(f%id, name, found, err)
    if (found) call h5adelete_f(f%id, name, err)
    if (n == 0) then
      call h5screate_f(H5S_SCALAR_F, space, err)
    else
      call h5screate_simple_f(1, [int(n, hsize_t)], space, err)
    end if
    call h5acreate_f(f%id, name, ftype, space, attr, err)
    if (err < 0) call fatal(here, 'cannot create attribute ' // name // ' in ' // f%path // &
      ': the file may be open read-only')
    call h5sclose_f(space, err)
  end function create_attr

  !> Open root attribute name and check that it holds n values.
  integer(hid_t) function open_attr(f, name, n) result(attr)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: n
    integer(hid_t) :: space
    integer(hsize_t) :: npoints
    integer :: err
    logical :: found
    call require_open(f, 'h5_read_attr')
    call h5aexists_f(f%id, name, found, err)
    if (err < 0 .or. .not. found) call fatal(here, 'attribute ' // name // ' not found in ' // &
      f%path // ': the file is not a SABRE file of this version')
    call h5aopen_f(f%id, name, attr, err)
    if (err < 0) call fatal(here, 'cannot open attribute ' // name // ' in ' // f%path)
    call h5aget_space_f(attr, space, err)
    call h5sget_simple_extent_npoints_f(space, npoints, err)
    call h5sclose_f(space, err)
    if (npoints /= int(n, hsize_t)) call fatal(here, 'attribute ' // name // ' in ' // &
      f%path // ' holds ' // int_text(int(npoints)) // ' values where ' // int_text(n) // &
      ' are expected: the file is not a SABRE file of this version')
  end function open_attr

  !> Close an attribute after a write (writing) or a read whose status was ioerr; fatal
  !> when that failed, or the close after a write.
  subroutine close_attr(f, name, attr, ioerr, writing)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: attr
    integer, intent(in) :: ioerr
    logical, intent(in) :: writing
    integer :: err
    call h5aclose_f(attr, err)
    if (writing .and. (ioerr < 0 .or. err < 0)) call fatal(here, 'cannot write attribute ' &
      // name // ' in ' // f%path // ': is the disk full?')
    if (.not. writing .and. ioerr < 0) call fatal(here, 'cannot read attribute ' // name // &
      ' from ' // f%path // ': its type does not match the variable (a string into a number?)')
  end subroutine close_attr

end module m_hdf5_attr
