!> Every HDF5 call of SABRE goes through this module (DESIGN section 7), the one the rest of
!> SABRE uses; it hands on the file routines of m_hdf5_file and the attributes of
!> m_hdf5_attr, and holds the grid, the fields and the text datasets. Plot and checkpoint
!> files hold GLOBAL datasets of Fortran shape (cells(1), cells(2), cells(3)) (h5py sees
!> (nz, ny, nx)); 1D and 2D runs still use 3D datasets with size 1 in the unused
!> directions. Files are opened with the MPI-IO driver on the world communicator; each rank
!> writes and reads the interior cells of its own blocks as hyperslabs with independent
!> transfers, so blocks may come back to a different owner than the one that wrote them
!> (restart on another rank count). A field dataset is stored in chunks of the nominal block
!> (lay%bsize), so that a block's interior is one piece of the file rather than a run per
!> row (block_chunk says when it stays contiguous); readers see the same array either way,
!> and a file of either layout restarts. Every public routine is collective: every rank
!> calls it, even one holding no block, because HDF5 creates files, groups, datasets and
!> attributes collectively. Attributes and text datasets store rank 0's value. Inactive
!> blocks are never written and read back as 0 (the datasets' fill value).
!> An HDF5 failure stops the run through fatal with the file and object named. This module
!> knows nothing of physics or of which fields exist; the XDMF companion file is m_xdmf's.
module m_hdf5_io
  use hdf5, only: hid_t, hsize_t, h5pcreate_f, h5pclose_f, h5pset_fill_value_f, &
    h5pset_chunk_f, h5pset_alloc_time_f, h5pset_fill_time_f, H5D_ALLOC_TIME_EARLY_F, &
    H5D_FILL_TIME_NEVER_F, H5P_DATASET_CREATE_F, h5screate_f, h5screate_simple_f, h5sclose_f, &
    h5sselect_hyperslab_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, &
    H5S_SCALAR_F, H5S_SELECT_SET_F, h5dcreate_f, h5dclose_f, h5dwrite_f, h5dread_f, &
    h5dget_space_f, h5dget_type_f, h5tclose_f, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE
  use m_kinds, only: wp
  use m_layout, only: layout_t, block_offset, block_extent
  use m_comm, only: comm_is_root, comm_bcast
  use m_errors, only: fatal
  use m_hdf5_file, only: h5_file_t, h5_init, h5_finalize, h5_create_file, h5_open_read, &
    h5_close, h5_exists, h5_has_attr, h5_is_hdf5, here, require_open, open_dataset, &
    link_create_list, string_type, string_size, unpadded_len, int_text, dims_text
  use m_hdf5_attr, only: h5_write_attr, h5_read_attr
  implicit none
  private
  public :: h5_file_t, h5_init, h5_finalize, h5_create, h5_open_read, h5_close
  public :: h5_write_attr, h5_read_attr, h5_write_field, h5_read_field, h5_read_field_halo
  public :: h5_write_text, h5_read_text, h5_exists, h5_has_attr, h5_is_hdf5

contains

  !> Create (truncate) a file collectively and write the grid: /grid/x, /grid/y, /grid/z
  !> (cell centres lo + (i - 1/2) dx) and the root attributes cells, lo, hi, ndim.
  subroutine h5_create(f, path, lay)
    type(h5_file_t), intent(out) :: f
    character(len=*), intent(in) :: path
    type(layout_t), intent(in) :: lay
    character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
    integer :: d, i
    real(wp), allocatable :: centres(:)
    call h5_create_file(f, path)
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
    integer(hid_t) :: dset, filespace, dcpl, lcpl
    integer(hsize_t) :: gdims(3), chunk(3)
    integer :: err
    call require_open(f, 'h5_write_field')
    call check_blocks(f, dset_path, lay, ids, shape(data))
    gdims = int(lay%cells, hsize_t)
    call h5screate_simple_f(3, gdims, filespace, err)
    call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl, err)
    call h5pset_fill_value_f(dcpl, H5T_NATIVE_DOUBLE, 0.0_wp, err)
    chunk = block_chunk(lay)
    if (all(chunk > 0)) then
      call h5pset_chunk_f(dcpl, 3, chunk, err)
      if (err < 0) call fatal(here, 'cannot set chunks of ' // dims_text(int(chunk)) // &
        ' cells for ' // dset_path // ' in ' // f%path)
      ! independent MPI-IO writes need every chunk allocated when the dataset is created;
      ! HDF5 1.10 forces it with the MPI-IO driver, asked for here so as not to rely on it
      call h5pset_alloc_time_f(dcpl, H5D_ALLOC_TIME_EARLY_F, err)
    end if
    ! the fill value is written at creation only where an inactive block leaves a hole:
    ! otherwise every cell would be written twice
    if (all(lay%active)) call h5pset_fill_time_f(dcpl, H5D_FILL_TIME_NEVER_F, err)
    lcpl = link_create_list()
    call h5dcreate_f(f%id, dset_path, H5T_IEEE_F64LE, filespace, dset, err, &
      dcpl_id=dcpl, lcpl_id=lcpl)
    if (err < 0) call fatal(here, 'cannot create dataset ' // dset_path // ' in ' // &
      f%path // ': is it written twice, or is the disk full?')
    call h5pclose_f(dcpl, err)
    call h5pclose_f(lcpl, err)
    call move_blocks(f, dset_path, dset, filespace, lay, ids, err, wdata=data)
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
    integer(hid_t) :: dset, filespace
    integer(hsize_t) :: gdims(3), maxdims(3)
    integer :: err, ndims
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
    data = 0.0_wp
    call move_blocks(f, dset_path, dset, filespace, lay, ids, err, rdata=data)
  end subroutine h5_read_field

  !> Read, for each of this rank's blocks, its interior cells and e cells beyond them on
  !> every side (as far as the domain reaches) from dset_path into data, whose cell
  !> (1 - e(d) .. nmax(d) + e(d)) is the block's; what lies beyond the domain's sides is left
  !> as the caller set it. For values a block needs from its neighbours' cells as they were
  !> written (the cut-cell update's fractions at the step's end), with no halo exchange.
  subroutine h5_read_field_halo(f, dset_path, lay, ids, e, data)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:), e(3)
    real(wp), intent(inout), contiguous :: data(:, :, :, :)
    integer(hid_t) :: dset, filespace, memspace
    integer(hsize_t) :: bdims(3), start(3), count(3), mstart(3)
    integer :: err, k, lo(3), hi(3)
    call require_open(f, 'h5_read_field_halo')
    dset = open_dataset(f, dset_path)
    call h5dget_space_f(dset, filespace, err)
    bdims = int(lay%nmax + 2 * e, hsize_t)
    call h5screate_simple_f(3, bdims, memspace, err)
    do k = 1, size(ids)
      if (.not. lay%active(ids(k))) cycle
      ! the block's cells and e beyond, clipped to the domain (0-based global indices)
      lo = max(block_offset(lay, ids(k)) - e, 0)
      hi = min(block_offset(lay, ids(k)) + block_extent(lay, ids(k)) + e, lay%cells) - 1
      start = int(lo, hsize_t)
      count = int(hi - lo + 1, hsize_t)
      mstart = int(lo - (block_offset(lay, ids(k)) - e), hsize_t)
      call h5sselect_hyperslab_f(filespace, H5S_SELECT_SET_F, start, count, err)
      call h5sselect_hyperslab_f(memspace, H5S_SELECT_SET_F, mstart, count, err)
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, data(:, :, :, k), bdims, err, &
        mem_space_id=memspace, file_space_id=filespace)
      if (err < 0) call fatal(here, 'cannot read block ' // int_text(ids(k)) // ' of ' // &
        dset_path // ' from ' // f%path // ': the file may be damaged')
    end do
    call h5sclose_f(memspace, err)
    call h5sclose_f(filespace, err)
    call h5dclose_f(dset, err)
  end subroutine h5_read_field_halo

  !> Write the blocks' cells from wdata or read them into rdata (one of them present,
  !> shaped as h5_write_field has it) between dataset dset, of dataspace filespace, and
  !> memory, block by block (inactive blocks skipped); then close the spaces and the
  !> dataset, err the status of the dataset's close.
  subroutine move_blocks(f, dset_path, dset, filespace, lay, ids, err, wdata, rdata)
    type(h5_file_t), intent(in) :: f
    character(len=*), intent(in) :: dset_path
    integer(hid_t), intent(in) :: dset, filespace
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:)
    integer, intent(out) :: err
    real(wp), intent(in), contiguous, optional :: wdata(:, :, :, :)
    real(wp), intent(inout), contiguous, optional :: rdata(:, :, :, :)
    integer(hid_t) :: memspace
    integer(hsize_t) :: bdims(3)
    integer :: k
    bdims = int(lay%nmax, hsize_t)
    call h5screate_simple_f(3, bdims, memspace, err)
    do k = 1, size(ids)
      if (.not. lay%active(ids(k))) cycle
      call select_block(filespace, lay, ids(k))
      call select_block(memspace, lay, ids(k), in_memory=.true.)
      if (present(wdata)) then
        call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, wdata(:, :, :, k), bdims, err, &
          mem_space_id=memspace, file_space_id=filespace)
        if (err < 0) call fatal(here, 'cannot write block ' // int_text(ids(k)) // ' of ' &
          // dset_path // ' in ' // f%path // ': is the disk full?')
      else
        call h5dread_f(dset, H5T_NATIVE_DOUBLE, rdata(:, :, :, k), bdims, err, &
          mem_space_id=memspace, file_space_id=filespace)
        if (err < 0) call fatal(here, 'cannot read block ' // int_text(ids(k)) // ' of ' // &
          dset_path // ' from ' // f%path // ': the file may be damaged')
      end if
    end do
    call h5sclose_f(memspace, err)
    call h5sclose_f(filespace, err)
    call h5dclose_f(dset, err)
  end subroutine move_blocks

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

  !> The chunk of a field dataset (Fortran order, as the dataspace): the nominal block
  !> lay%bsize, so that every block that is not the last along a direction is exactly one
  !> chunk, one piece of the file, and the last block is whole chunks and part of one more
  !> (it may hold up to n_halo - 1 cells more than bsize). 0 keeps the dataset contiguous:
  !> - when the blocks are slabs (one block across every direction but the slowest, as in
  !>   every 1D run): a contiguous dataset already holds each block in one piece;
  !> - when a chunk would pass HDF5's limit of 4 GiB (a block of 2^29 cells, 812^3);
  !> - when chunks would make the file more than max_growth larger than its data: HDF5
  !>   stores a partial chunk at the edge of the grid whole, and indexes every chunk (about
  !>   60 bytes a chunk, measured; index_bytes rounds it up). So 98^3 cells in 32^3 blocks (2.2
  !>   times the data) or
  !>   blocks of 4^3 cells (512-byte chunks, 12 % index) stay contiguous, while 256^3 in
  !>   32^3 (0.03 %) or 1000^3 in 32^3 (7 % of edge chunks) are chunked.
  pure function block_chunk(lay) result(chunk)
    type(layout_t), intent(in) :: lay
    integer(hsize_t) :: chunk(3)
    integer(hsize_t), parameter :: max_chunk_bytes = 4294967295_hsize_t
    real(wp), parameter :: index_bytes = 64.0_wp, max_growth = 0.10_wp
    real(wp) :: nchunks(3), stored
    chunk = 0
    if (all(lay%nb(1:lay%ndim - 1) == 1)) return
    if (8_hsize_t * product(int(lay%bsize, hsize_t)) > max_chunk_bytes) return
    nchunks = real((lay%cells + lay%bsize - 1) / lay%bsize, wp)
    stored = 8.0_wp * product(nchunks * lay%bsize) + index_bytes * product(nchunks)
    if (stored > (1.0_wp + max_growth) * 8.0_wp * product(real(lay%cells, wp))) return
    chunk = int(lay%bsize, hsize_t)
  end function block_chunk

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

end module m_hdf5_io
