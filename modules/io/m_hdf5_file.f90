!> HDF5 files of SABRE (DESIGN section 7), the bottom of the HDF5 layer: the library, the
!> file handle, opening and closing files with the MPI-IO driver on the world communicator
!> (its handle from m_comm), what a file holds, and the helpers that the layer's other
!> modules share (m_hdf5_attr: attributes; m_hdf5_io: grid, fields and text, and the one
!> module the rest of SABRE uses). Every public routine is collective: every rank calls it,
!> even one holding no block, because HDF5 opens and creates files collectively.
!> An HDF5 failure stops the run through fatal with the file and object named; messages
!> name the layer m_hdf5_io, whichever of its modules sees the failure.
module m_hdf5_file
  use hdf5, only: hid_t, size_t, h5open_f, h5close_f, h5eset_auto_f, h5fcreate_f, h5fopen_f, &
    h5fclose_f, h5fis_hdf5_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, h5pcreate_f, h5pclose_f, &
    h5pset_fapl_mpio_f, h5pset_create_inter_group_f, H5P_FILE_ACCESS_F, H5P_LINK_CREATE_F, &
    h5dopen_f, h5aexists_f, h5lexists_f, h5tcopy_f, h5tset_size_f, h5tget_size_f, &
    h5tset_strpad_f, h5tget_class_f, H5T_NATIVE_CHARACTER, H5T_STR_NULLPAD_F, H5T_STRING_F
  use m_comm, only: comm_world_handles
  use m_errors, only: fatal
  use m_text, only: int_text
  implicit none
  private
  public :: h5_file_t, h5_init, h5_finalize, h5_create_file, h5_open_read, h5_close
  public :: h5_exists, h5_has_attr, h5_is_hdf5
  ! for the modules of the HDF5 layer
  public :: here, require_open, open_dataset, link_create_list, string_type, string_size
  public :: unpadded_len, int_text, dims_text

  character(len=*), parameter :: here = 'm_hdf5_io'

  !> An open HDF5 file. Only the modules of the HDF5 layer look inside.
  type :: h5_file_t
    integer(hid_t) :: id = -1
    character(len=:), allocatable :: path
  end type h5_file_t

contains

  !> Open the HDF5 library once per run. HDF5's own error stack printing is switched off:
  !> every failure is reported by fatal with the file and object it concerns.
  subroutine h5_init()
    integer :: err
    call h5open_f(err)
    if (err < 0) call fatal(here, 'cannot initialise the HDF5 library: check that the ' // &
      'parallel HDF5 runtime matches the one SABRE was built with')
    call h5eset_auto_f(0, err)
  end subroutine h5_init

  subroutine h5_finalize()
    integer :: err
    call h5close_f(err)
    if (err < 0) call fatal(here, 'cannot close the HDF5 library: an object was left open')
  end subroutine h5_finalize

  !> Create (truncate) an empty file collectively (h5_create of m_hdf5_io adds the grid).
  subroutine h5_create_file(f, path)
    type(h5_file_t), intent(out) :: f
    character(len=*), intent(in) :: path
    logical :: ok
    call open_file(f, path, .true., ok)
    if (.not. ok) call fatal(here, 'cannot create ' // f%path // &
      ': check that its folder exists and is writable on every rank')
  end subroutine h5_create_file

  !> Open an existing file collectively, read-only.
  subroutine h5_open_read(f, path)
    type(h5_file_t), intent(out) :: f
    character(len=*), intent(in) :: path
    logical :: found, ok
    inquire(file=trim(path), exist=found)
    if (.not. found) call fatal(here, 'file ' // trim(path) // ' not found: check the ' // &
      'path (restart = ... in &run names a chk_NNNNNN.h5 file)')
    call open_file(f, path, .false., ok)
    if (.not. ok) call fatal(here, 'cannot open ' // f%path // &
      ': it is not a readable HDF5 file (truncated by a crash? wrong file?)')
  end subroutine h5_open_read

  !> Create (truncate) or open read-only path with the MPI-IO driver; ok false on failure.
  subroutine open_file(f, path, create, ok)
    type(h5_file_t), intent(inout) :: f
    character(len=*), intent(in) :: path
    logical, intent(in) :: create
    logical, intent(out) :: ok
    integer(hid_t) :: fapl
    integer :: err
    f%path = trim(path)
    fapl = mpio_access_list(f%path)
    if (create) then
      call h5fcreate_f(f%path, H5F_ACC_TRUNC_F, f%id, err, access_prp=fapl)
    else
      call h5fopen_f(f%path, H5F_ACC_RDONLY_F, f%id, err, access_prp=fapl)
    end if
    call h5pclose_f(fapl, err)
    ok = err >= 0 .and. f%id >= 0
  end subroutine open_file

  !> Whether path is an HDF5 file (false for a missing or another kind of file); opens
  !> nothing, so that a wrong file can be refused before any output is written.
  logical function h5_is_hdf5(path) result(is_hdf5)
    character(len=*), intent(in) :: path
    integer :: err
    logical :: found
    is_hdf5 = .false.
    inquire(file=trim(path), exist=found)
    if (.not. found) return
    call h5fis_hdf5_f(trim(path), is_hdf5, err)
    is_hdf5 = is_hdf5 .and. err >= 0
  end function h5_is_hdf5

  !> Close a file collectively; closing a file that is not open does nothing.
  subroutine h5_close(f)
    type(h5_file_t), intent(inout) :: f
    integer :: err
    if (f%id < 0) return
    call h5fclose_f(f%id, err)
    if (err < 0) call fatal(here, 'cannot close ' // f%path // &
      ': the disk may be full, or an HDF5 object in it was left open')
    f%id = -1
  end subroutine h5_close

  !> True when the object dset_path (a group, dataset, ...) exists in the file.
  logical function h5_exists(f, dset_path) result(found)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    call require_open(f, 'h5_exists')
    found = path_exists(f, dset_path)
  end function h5_exists

  !> True when the file's root carries the attribute name (for attributes that a
  !> checkpoint of an earlier version may lack).
  logical function h5_has_attr(f, name) result(found)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer :: err
    call require_open(f, 'h5_has_attr')
    call h5aexists_f(f%id, name, found, err)
    found = found .and. err >= 0
  end function h5_has_attr

  ! ---------------------------------------------------------------------------------------
  ! Helpers of the HDF5 layer
  ! ---------------------------------------------------------------------------------------

  !> A file access property list for the MPI-IO driver on all ranks. The HDF5 1.10
  !> Fortran interface takes the old integer handles, which m_comm hands out.
  integer(hid_t) function mpio_access_list(path) result(fapl)
    character(len=*), intent(in) :: path
    integer :: err, mpi_comm, mpi_info
    call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, err)
    call comm_world_handles(mpi_comm, mpi_info)
    call h5pset_fapl_mpio_f(fapl, mpi_comm, mpi_info, err)
    if (err < 0) call fatal(here, 'cannot set up MPI-IO access to ' // path // &
      ': is the HDF5 library the parallel (openmpi) build?')
  end function mpio_access_list

  !> A link creation property list that creates missing intermediate groups.
  integer(hid_t) function link_create_list() result(lcpl)
    integer :: err
    call h5pcreate_f(H5P_LINK_CREATE_F, lcpl, err)
    call h5pset_create_inter_group_f(lcpl, 1, err)
  end function link_create_list

  !> A fixed-length string type of n characters, NUL-padded as numpy's 'S' strings are.
  integer(hid_t) function string_type(n) result(stype)
    integer, intent(in) :: n
    integer :: err
    call h5tcopy_f(H5T_NATIVE_CHARACTER, stype, err)
    call h5tset_size_f(stype, int(n, size_t), err)
    call h5tset_strpad_f(stype, H5T_STR_NULLPAD_F, err)
  end function string_type

  !> Length of the fixed-length string type ftype; fatal when it is not a string.
  integer function string_size(ftype, what, f) result(n)
    integer(hid_t), intent(in) :: ftype
    character(len=*), intent(in) :: what
    type(h5_file_t), intent(in) :: f
    integer :: err, tclass
    integer(size_t) :: tsize
    call h5tget_class_f(ftype, tclass, err)
    if (tclass /= H5T_STRING_F) call fatal(here, what // ' in ' // f%path // &
      ' is not a string: the file was not written by SABRE')
    call h5tget_size_f(ftype, tsize, err)
    n = int(tsize)
  end function string_size

  !> Length of buf without its trailing NUL padding.
  pure integer function unpadded_len(buf) result(n)
    character(len=*), intent(in) :: buf
    n = len(buf)
    do while (n > 0)
      if (buf(n:n) /= achar(0)) exit
      n = n - 1
    end do
  end function unpadded_len

  !> Open an existing dataset; a missing one is a fatal error naming file and dataset.
  integer(hid_t) function open_dataset(f, dset_path) result(dset)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    integer :: err
    if (.not. path_exists(f, dset_path)) call fatal(here, 'dataset ' // dset_path // &
      ' not found in ' // f%path // ': the file was written by a run without this ' // &
      'field, or is not a SABRE file')
    call h5dopen_f(f%id, dset_path, dset, err)
    if (err < 0) call fatal(here, 'cannot open ' // dset_path // ' in ' // f%path // &
      ' as a dataset: is it a group?')
  end function open_dataset

  !> Whether every link along path exists: h5lexists_f is asked about each prefix in turn
  !> because it fails, rather than answering false, on a missing intermediate group.
  logical function path_exists(f, path) result(found)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: path
    integer :: err, pos, k, last
    found = .false.
    if (len_trim(path) == 0) return
    pos = 1
    if (path(1:1) == '/') pos = 2
    do while (pos <= len_trim(path))
      k = index(path(pos:), '/')
      last = len_trim(path)
      if (k > 0) last = pos + k - 2
      call h5lexists_f(f%id, path(1:last), found, err)
      if (err < 0) found = .false.
      if (.not. found .or. k == 0) return
      pos = last + 2
    end do
  end function path_exists

  subroutine require_open(f, routine)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: routine
    if (f%id < 0) call fatal(here, routine // ' called on a file that is not open ' // &
      '(a bug in the caller: h5_create or h5_open_read first)')
  end subroutine require_open

  !> Integers joined by x, as a shape is written: 12x8x16.
  pure function dims_text(d) result(s)
    integer, intent(in) :: d(:)
    character(len=:), allocatable :: s
    character(len=12 * size(d)) :: buf
    write(buf, '(*(i0, :, "x"))') d
    s = trim(buf)
  end function dims_text

end module m_hdf5_file
