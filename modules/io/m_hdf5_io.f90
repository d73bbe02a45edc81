!> Every HDF5 call of SABRE (DESIGN section 7): plot and checkpoint files hold GLOBAL datasets
!> of Fortran shape (cells(1), cells(2), cells(3)) (h5py sees (nz, ny, nx)); 1D and 2D runs
!> still use 3D datasets with size 1 in the unused directions. Files are opened with the
!> MPI-IO driver on the world communicator (its handle from m_comm); each rank writes and
!> reads the interior cells of its own blocks as hyperslabs with independent transfers, so
!> blocks may come back to a different owner than the one that wrote them (restart on
!> another rank count). Every public routine is collective: every rank calls it, even one
!> holding no block, because HDF5 creates files, groups, datasets and attributes
!> collectively. Attributes and text datasets store rank 0's value. Inactive blocks are
!> never written and read back as 0 (the datasets' fill value).
!> An HDF5 failure stops the run through fatal with the file and object named. This module
!> knows nothing of physics or of which fields exist; the XDMF companion file is m_xdmf's.
module m_hdf5_io
  use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5close_f, h5eset_auto_f, &
    h5fcreate_f, h5fopen_f, h5fclose_f, h5fis_hdf5_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, &
    h5pcreate_f, h5pclose_f, h5pset_fapl_mpio_f, h5pset_fill_value_f, &
    h5pset_create_inter_group_f, H5P_FILE_ACCESS_F, H5P_DATASET_CREATE_F, H5P_LINK_CREATE_F, &
    h5screate_f, h5screate_simple_f, h5sclose_f, h5sselect_hyperslab_f, &
    h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
    h5sget_simple_extent_npoints_f, H5S_SCALAR_F, H5S_SELECT_SET_F, &
    h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, h5dread_f, h5dget_space_f, h5dget_type_f, &
    h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, h5aexists_f, h5adelete_f, &
    h5aget_space_f, h5aget_type_f, h5lexists_f, &
    h5tcopy_f, h5tclose_f, h5tset_size_f, h5tget_size_f, h5tset_strpad_f, h5tget_class_f, &
    H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_NATIVE_CHARACTER, H5T_IEEE_F64LE, &
    H5T_STD_I32LE, H5T_STR_NULLPAD_F, H5T_STRING_F
  use m_kinds, only: wp
  use m_layout, only: layout_t, block_offset, block_extent
  use m_comm, only: comm_is_root, comm_bcast, comm_world_handles
  use m_errors, only: fatal
  implicit none
  private
  public :: h5_file_t, h5_init, h5_finalize, h5_create, h5_open_read, h5_close
  public :: h5_write_attr, h5_read_attr, h5_write_field, h5_read_field
  public :: h5_write_text, h5_read_text, h5_exists, h5_has_attr, h5_is_hdf5

  character(len=*), parameter :: here = 'm_hdf5_io'

  !> An open HDF5 file. Opaque: only this module looks inside.
  type :: h5_file_t
    private
    integer(hid_t) :: id = -1
    character(len=:), allocatable :: path
  end type h5_file_t

  interface h5_write_attr
    module procedure write_attr_real, write_attr_int, write_attr_real_array, &
      write_attr_int_array, write_attr_string
  end interface h5_write_attr

  interface h5_read_attr
    module procedure read_attr_real, read_attr_int, read_attr_real_array, &
      read_attr_int_array, read_attr_string
  end interface h5_read_attr

contains

  ! ---------------------------------------------------------------------------------------
  ! Library and files
  ! ---------------------------------------------------------------------------------------

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

  !> Create (truncate) a file collectively and write the grid: /grid/x, /grid/y, /grid/z
  !> (cell centres lo + (i - 1/2) dx) and the root attributes cells, lo, hi, ndim.
  subroutine h5_create(f, path, lay)
    type(h5_file_t), intent(out) :: f
    character(len=*), intent(in) :: path
    type(layout_t), intent(in) :: lay
    character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
    integer(hid_t) :: fapl
    integer :: err, d, i
    real(wp), allocatable :: centres(:)
    f%path = trim(path)
    fapl = mpio_access_list(f%path)
    call h5fcreate_f(f%path, H5F_ACC_TRUNC_F, f%id, err, access_prp=fapl)
    call h5pclose_f(fapl, err)
    if (err < 0 .or. f%id < 0) call fatal(here, 'cannot create ' // f%path // &
      ': check that its folder exists and is writable on every rank')
    do d = 1, 3
      allocate(centres(lay%cells(d)))
      do i = 1, lay%cells(d)
        centres(i) = lay%lo(d) + (real(i, wp) - 0.5_wp) * lay%dx(d)
      end do
      call write_real_vector(f, '/grid/' // axis(d), centres)
      deallocate(centres)
    end do
    call h5_write_attr(f, 'cells', lay%cells)
    call h5_write_attr(f, 'lo', lay%lo)
    call h5_write_attr(f, 'hi', lay%hi)
    call h5_write_attr(f, 'ndim', lay%ndim)
  end subroutine h5_create

  !> Open an existing file collectively, read-only.
  subroutine h5_open_read(f, path)
    type(h5_file_t), intent(out) :: f
    character(len=*), intent(in) :: path
    integer(hid_t) :: fapl
    integer :: err
    logical :: found
    f%path = trim(path)
    inquire(file=f%path, exist=found)
    if (.not. found) call fatal(here, 'file ' // f%path // ' not found: check the path ' // &
      '(restart = ... in &run names a chk_NNNNNN.h5 file)')
    fapl = mpio_access_list(f%path)
    call h5fopen_f(f%path, H5F_ACC_RDONLY_F, f%id, err, access_prp=fapl)
    call h5pclose_f(fapl, err)
    if (err < 0 .or. f%id < 0) call fatal(here, 'cannot open ' // f%path // &
      ': it is not a readable HDF5 file (truncated by a crash? wrong file?)')
  end subroutine h5_open_read

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
  ! Fields: one global dataset per field, one hyperslab per block
  ! ---------------------------------------------------------------------------------------

  !> Write the interior cells of this rank's blocks: data(:, :, :, k) is block ids(k), at the
  !> largest block extent (lay%nmax): its first block_extent cells along each direction are
  !> the block's. Creates dset_path (and any missing groups on the way) with fill value 0.
  subroutine h5_write_field(f, dset_path, lay, ids, data)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:)
    real(wp), intent(in), contiguous :: data(:, :, :, :)
    integer(hid_t) :: dset, filespace, memspace, dcpl, lcpl
    integer(hsize_t) :: gdims(3), bdims(3)
    integer :: err, k
    call require_open(f, 'h5_write_field')
    call check_blocks(f, dset_path, lay, ids, shape(data))
    gdims = int(lay%cells, hsize_t)
    bdims = int(lay%nmax, hsize_t)
    call h5screate_simple_f(3, gdims, filespace, err)
    call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, err)
    call h5pset_fill_value_f(dcpl, H5T_NATIVE_DOUBLE, 0.0_wp, err)
    lcpl = link_create_list()
    call h5dcreate_f(f%id, dset_path, H5T_IEEE_F64LE, filespace, dset, err, &
      dcpl_id=dcpl, lcpl_id=lcpl)
    if (err < 0) call fatal(here, 'cannot create dataset ' // dset_path // ' in ' // &
      f%path // ': is it written twice, or is the disk full?')
    call h5pclose_f(dcpl, err)
    call h5pclose_f(lcpl, err)
    call h5screate_simple_f(3, bdims, memspace, err)
    do k = 1, size(ids)
      if (.not. lay%active(ids(k))) cycle
      call select_block(filespace, lay, ids(k))
      call select_block(memspace, lay, ids(k), in_memory=.true.)
      call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, data(:, :, :, k), bdims, err, &
        mem_space_id=memspace, file_space_id=filespace)
      if (err < 0) call fatal(here, 'cannot write block ' // int_text(ids(k)) // ' of ' // &
        dset_path // ' in ' // f%path // ': is the disk full?')
    end do
    call h5sclose_f(memspace, err)
    call h5sclose_f(filespace, err)
    call h5dclose_f(dset, err)
    if (err < 0) call fatal(here, 'cannot close dataset ' // dset_path // ' in ' // f%path)
  end subroutine h5_write_field

  !> Read the interior cells of this rank's blocks from dset_path, whichever rank wrote
  !> them, into data as h5_write_field has it. An inactive block comes back as 0.
  subroutine h5_read_field(f, dset_path, lay, ids, data)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:)
    real(wp), intent(out), contiguous :: data(:, :, :, :)
    integer(hid_t) :: dset, filespace, memspace
    integer(hsize_t) :: gdims(3), maxdims(3), bdims(3)
    integer :: err, k, ndims
    call require_open(f, 'h5_read_field')
    call check_blocks(f, dset_path, lay, ids, shape(data))
    dset = open_dataset(f, dset_path)
    call h5dget_space_f(dset, filespace, err)
    call h5sget_simple_extent_ndims_f(filespace, ndims, err)
    if (ndims /= 3) call fatal(here, 'dataset ' // dset_path // ' in ' // f%path // &
      ' has rank ' // int_text(ndims) // ', not 3: it is not a SABRE field')
    call h5sget_simple_extent_dims_f(filespace, gdims, maxdims, err)
    if (any(gdims /= int(lay%cells, hsize_t))) call fatal(here, 'dataset ' // dset_path // &
      ' in ' // f%path // ' holds ' // dims_text(int(gdims)) // ' cells but the run has ' // &
      dims_text(lay%cells) // ': restart with the &domain cells of the run that wrote it')
    bdims = int(lay%nmax, hsize_t)
    call h5screate_simple_f(3, bdims, memspace, err)
    do k = 1, size(ids)
      data(:, :, :, k) = 0.0_wp
      if (.not. lay%active(ids(k))) cycle
      call select_block(filespace, lay, ids(k))
      call select_block(memspace, lay, ids(k), in_memory=.true.)
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, data(:, :, :, k), bdims, err, &
        mem_space_id=memspace, file_space_id=filespace)
      if (err < 0) call fatal(here, 'cannot read block ' // int_text(ids(k)) // ' of ' // &
        dset_path // ' from ' // f%path // ': the file may be damaged')
    end do
    call h5sclose_f(memspace, err)
    call h5sclose_f(filespace, err)
    call h5dclose_f(dset, err)
  end subroutine h5_read_field

  ! ---------------------------------------------------------------------------------------
  ! Text: one scalar fixed-length string dataset (rank 0's text), e.g. the resolved deck
  ! ---------------------------------------------------------------------------------------

  subroutine h5_write_text(f, dset_path, text)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path, text
    integer(hid_t) :: dset, space, stype, lcpl
    integer(hsize_t) :: one(1)
    integer :: err, n
    call require_open(f, 'h5_write_text')
    n = 0
    if (comm_is_root()) n = len(text)
    call comm_bcast(n, 0)
    one = 1
    ! HDF5 has no zero-length string type: an empty text is one NUL, which is padding.
    stype = string_type(max(n, 1))
    call h5screate_f(H5S_SCALAR_F, space, err)
    lcpl = link_create_list()
    call h5dcreate_f(f%id, dset_path, stype, space, dset, err, lcpl_id=lcpl)
    if (err < 0) call fatal(here, 'cannot create text dataset ' // dset_path // ' in ' // &
      f%path // ': is it written twice?')
    call h5pclose_f(lcpl, err)
    if (comm_is_root()) then
      if (n > 0) then
        call h5dwrite_f(dset, stype, text, one, err)
      else
        call h5dwrite_f(dset, stype, achar(0), one, err)
      end if
      if (err < 0) call fatal(here, 'cannot write text ' // dset_path // ' in ' // f%path)
    end if
    call h5sclose_f(space, err)
    call h5tclose_f(stype, err)
    call h5dclose_f(dset, err)
  end subroutine h5_write_text

  !> Read a text dataset on every rank; trailing NUL padding is dropped.
  subroutine h5_read_text(f, dset_path, text)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    character(len=:), allocatable, intent(out) :: text
    integer(hid_t) :: dset, ftype, stype
    integer(hsize_t) :: one(1)
    integer :: err, n
    character(len=:), allocatable :: buf
    call require_open(f, 'h5_read_text')
    dset = open_dataset(f, dset_path)
    call h5dget_type_f(dset, ftype, err)
    n = string_size(ftype, dset_path, f)
    call h5tclose_f(ftype, err)
    stype = string_type(n)
    allocate(character(len=n) :: buf)
    one = 1
    call h5dread_f(dset, stype, buf, one, err)
    if (err < 0) call fatal(here, 'cannot read text ' // dset_path // ' from ' // f%path)
    call h5tclose_f(stype, err)
    call h5dclose_f(dset, err)
    text = buf(1:unpadded_len(buf))
  end subroutine h5_read_text

  ! ---------------------------------------------------------------------------------------
  ! Attributes of the root group. Writers store rank 0's value; an existing attribute of
  ! the same name is replaced. Readers run on every rank.
  ! ---------------------------------------------------------------------------------------

  subroutine write_attr_real(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value
    real(wp) :: v(1)
    integer(hid_t) :: attr
    integer :: err
    v(1) = value
    call comm_bcast(v(1), 0)
    attr = create_attr(f, name, H5T_IEEE_F64LE, 0)
    call h5awrite_f(attr, H5T_NATIVE_DOUBLE, v, [1_hsize_t], err)
    call finish_attr_write(f, name, attr, err)
  end subroutine write_attr_real

  subroutine write_attr_int(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: value
    integer :: v(1)
    integer(hid_t) :: attr
    integer :: err
    v(1) = value
    call comm_bcast(v(1), 0)
    attr = create_attr(f, name, H5T_STD_I32LE, 0)
    call h5awrite_f(attr, H5T_NATIVE_INTEGER, v, [1_hsize_t], err)
    call finish_attr_write(f, name, attr, err)
  end subroutine write_attr_int

  subroutine write_attr_real_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: value(:)
    real(wp) :: v(size(value))
    integer(hid_t) :: attr
    integer :: err, i
    v = value
    do i = 1, size(v)
      call comm_bcast(v(i), 0)
    end do
    attr = create_attr(f, name, H5T_IEEE_F64LE, size(v))
    call h5awrite_f(attr, H5T_NATIVE_DOUBLE, v, [int(size(v), hsize_t)], err)
    call finish_attr_write(f, name, attr, err)
  end subroutine write_attr_real_array

  subroutine write_attr_int_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(in) :: value(:)
    integer :: v(size(value))
    integer(hid_t) :: attr
    integer :: err
    v = value
    call comm_bcast(v, 0)
    attr = create_attr(f, name, H5T_STD_I32LE, size(v))
    call h5awrite_f(attr, H5T_NATIVE_INTEGER, v, [int(size(v), hsize_t)], err)
    call finish_attr_write(f, name, attr, err)
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
    call finish_attr_write(f, name, attr, err)
  end subroutine write_attr_string

  subroutine read_attr_real(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: value
    real(wp) :: v(1)
    integer(hid_t) :: attr
    integer :: err
    attr = open_attr(f, name, 1)
    call h5aread_f(attr, H5T_NATIVE_DOUBLE, v, [1_hsize_t], err)
    call finish_attr_read(f, name, attr, err)
    value = v(1)
  end subroutine read_attr_real

  subroutine read_attr_int(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(out) :: value
    integer :: v(1)
    integer(hid_t) :: attr
    integer :: err
    attr = open_attr(f, name, 1)
    call h5aread_f(attr, H5T_NATIVE_INTEGER, v, [1_hsize_t], err)
    call finish_attr_read(f, name, attr, err)
    value = v(1)
  end subroutine read_attr_int

  subroutine read_attr_real_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: value(:)
    real(wp) :: v(size(value))
    integer(hid_t) :: attr
    integer :: err
    attr = open_attr(f, name, size(value))
    call h5aread_f(attr, H5T_NATIVE_DOUBLE, v, [int(size(v), hsize_t)], err)
    call finish_attr_read(f, name, attr, err)
    value = v
  end subroutine read_attr_real_array

  subroutine read_attr_int_array(f, name, value)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer, intent(out) :: value(:)
    integer :: v(size(value))
    integer(hid_t) :: attr
    integer :: err
    attr = open_attr(f, name, size(value))
    call h5aread_f(attr, H5T_NATIVE_INTEGER, v, [int(size(v), hsize_t)], err)
    call finish_attr_read(f, name, attr, err)
    value = v
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
    call finish_attr_read(f, name, attr, err)
    n = unpadded_len(buf)
    if (len_trim(buf(1:n)) > len(value)) call fatal(here, 'attribute ' // name // ' of ' // &
      f%path // ' has ' // int_text(len_trim(buf(1:n))) // ' characters, more than the ' // &
      int_text(len(value)) // ' of the variable it is read into: lengthen that variable')
    value = buf(1:n)
  end subroutine read_attr_string

  ! ---------------------------------------------------------------------------------------
  ! Helpers
  ! ---------------------------------------------------------------------------------------

  !> A 1D float64 dataset created by all ranks and filled by rank 0.
  subroutine write_real_vector(f, dset_path, values)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    real(wp), intent(in) :: values(:)
    integer(hid_t) :: dset, space, lcpl
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = int(size(values), hsize_t)
    call h5screate_simple_f(1, dims, space, err)
    lcpl = link_create_list()
    call h5dcreate_f(f%id, dset_path, H5T_IEEE_F64LE, space, dset, err, lcpl_id=lcpl)
    if (err < 0) call fatal(here, 'cannot create dataset ' // dset_path // ' in ' // f%path)
    call h5pclose_f(lcpl, err)
    if (comm_is_root()) then
      call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, dims, err)
      if (err < 0) call fatal(here, 'cannot write ' // dset_path // ' in ' // f%path // &
        ': is the disk full?')
    end if
    call h5sclose_f(space, err)
    call h5dclose_f(dset, err)
  end subroutine write_real_vector

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

  subroutine finish_attr_write(f, name, attr, werr)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: attr
    integer, intent(in) :: werr
    integer :: err
    call h5aclose_f(attr, err)
    if (werr < 0 .or. err < 0) call fatal(here, 'cannot write attribute ' // name // &
      ' in ' // f%path // ': is the disk full?')
  end subroutine finish_attr_write

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

  subroutine finish_attr_read(f, name, attr, rerr)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: name
    integer(hid_t), intent(in) :: attr
    integer, intent(in) :: rerr
    integer :: err
    call h5aclose_f(attr, err)
    if (rerr < 0) call fatal(here, 'cannot read attribute ' // name // ' from ' // &
      f%path // ': its type does not match the variable (a string into a number?)')
  end subroutine finish_attr_read

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

  !> Select the interior cells of block id in the global dataspace, or (in_memory) in the
  !> block's buffer of the largest block extent.
  subroutine select_block(space, lay, id, in_memory)
    integer(hid_t), intent(in) :: space
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    logical, intent(in), optional :: in_memory
    integer(hsize_t) :: start(3), count(3)
    integer :: err
    start = int(block_offset(lay, id), hsize_t)
    if (present(in_memory)) start = 0
    count = int(block_extent(lay, id), hsize_t)
    call h5sselect_hyperslab_f(space, H5S_SELECT_SET_F, start, count, err)
    if (err < 0) call fatal(here, 'cannot select block ' // int_text(id) // &
      ' in the file dataspace: the layout does not match the dataset')
  end subroutine select_block

  !> Block ids in range and data of shape (nmax, size(ids)).
  subroutine check_blocks(f, dset_path, lay, ids, data_shape)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:), data_shape(4)
    if (any(data_shape(1:3) /= lay%nmax) .or. data_shape(4) /= size(ids)) &
      call fatal(here, dset_path // ' of ' // f%path // ': data has shape ' // &
      dims_text(data_shape) // ', not the block size ' // dims_text(lay%nmax) // &
      ' times ' // int_text(size(ids)) // ' blocks (a bug in the caller)')
    if (size(ids) == 0) return
    if (minval(ids) < 1 .or. maxval(ids) > lay%nblocks) call fatal(here, dset_path // &
      ' of ' // f%path // ': block id out of 1..' // int_text(lay%nblocks) // &
      ' (a bug in the caller)')
  end subroutine check_blocks

  subroutine require_open(f, routine)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: routine
    if (f%id < 0) call fatal(here, routine // ' called on a file that is not open ' // &
      '(a bug in the caller: h5_create or h5_open_read first)')
  end subroutine require_open

  pure function int_text(i) result(s)
    integer, intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: buf
    write(buf, '(i0)') i
    s = trim(buf)
  end function int_text

  pure function dims_text(d) result(s)
    integer, intent(in) :: d(:)
    character(len=:), allocatable :: s
    integer :: i
    s = int_text(d(1))
    do i = 2, size(d)
      s = s // 'x' // int_text(d(i))
    end do
  end function dims_text

end module m_hdf5_io
