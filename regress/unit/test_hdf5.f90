!> Unit test of m_hdf5_io (and the m_xdmf companion file). For a 1D, a 2D and a 3D layout
!> with several blocks per rank and some inactive blocks, each block's data a known function
!> of the global cell index, it writes a file, then reads it back into the blocks of a
!> DIFFERENT owner assignment (what a restart on another rank count sees) and checks every
!> value bit for bit, that inactive blocks read back as 0, that attributes and the text
!> dataset round-trip with rank 0's value, and the root grid attributes. In the 3D case the
!> last rank holds no block when writing, so the collective calls are exercised with nloc = 0.
!> The .xmf companion's mesh is checked too (1D and 2D flat along their unused directions),
!> and the storage of a field dataset: chunks of the block, or contiguous (m_hdf5_io's
!> block_chunk), read back with the HDF5 library itself.
!> Prints PASS test_hdf5 or FAIL ... and exits non-zero on failure. With --keep the files
!> (test_hdf5_{1d,2d,3d}.h5 and .xmf in the working folder) are kept for inspection.
program test_hdf5
  use m_kinds, only: wp, i8
  use m_comm, only: comm_init, comm_rank, comm_size, comm_is_root, comm_barrier
  use m_test_check, only: check_start, check, check_done, int_text
  use m_layout, only: layout_t, layout_init, block_offset, block_extent
  use m_hdf5_io, only: h5_file_t, h5_init, h5_finalize, h5_create, h5_open_read, h5_close, &
    h5_write_attr, h5_read_attr, h5_write_field, h5_read_field, h5_write_text, &
    h5_read_text, h5_exists, h5_has_attr
  use m_xdmf, only: xdmf_write
  use hdf5, only: hid_t, hsize_t, h5fopen_f, h5fclose_f, h5dopen_f, h5dclose_f, &
    h5dget_create_plist_f, h5pget_layout_f, h5pget_chunk_f, h5pclose_f, H5F_ACC_RDONLY_F, &
    H5D_CHUNKED_F
  implicit none

  integer, parameter :: n_fields = 3
  character(len=*), parameter :: field_path(n_fields) = &
    [character(len=16) :: '/fields/rho', '/fields/p', '/state/deep/q1']
  integer :: i
  logical :: keep
  character(len=64) :: arg

  call comm_init()
  call h5_init()
  keep = .false.
  do i = 1, command_argument_count()
    call get_command_argument(i, arg)
    if (trim(arg) == '--keep') keep = .true.
  end do

  call check_start('test_hdf5')
  ! the expected chunks: 0 for a contiguous dataset (1D; blocks of 128 and 512 bytes, whose
  ! chunk index would pass 10 % of the data)
  call run_case('1d', 1, [64, 1, 1], [8, 1, 1], [-1.0_wp, 0.0_wp, 0.0_wp], &
    [2.0_wp, 1.0_wp, 1.0_wp], [3], .false., [0, 0, 0])
  call run_case('2d', 2, [24, 16, 1], [4, 4, 1], [-1.0_wp, 0.25_wp, 0.0_wp], &
    [2.0_wp, 1.5_wp, 1.0_wp], [8, 15], .false., [0, 0, 0])
  call run_case('3d', 3, [12, 8, 16], [4, 4, 4], [-1.0_wp, 0.25_wp, 3.0_wp], &
    [2.0_wp, 1.5_wp, 4.0_wp], [5, 18], .true., [0, 0, 0])
  ! cells not a multiple of block: last blocks of 6 (x) and 10 (y: 2 cells joined) cells
  call run_case('2d_uneven', 2, [30, 18, 1], [8, 8, 1], [-1.0_wp, 0.25_wp, 0.0_wp], &
    [2.0_wp, 1.5_wp, 1.0_wp], [6], .false., [0, 0, 0])
  ! chunked by block, with inactive blocks (the fill value written) and without, where the
  ! last block along x (10 cells: 2 joined) is one chunk and 2 cells of a partial one
  call run_case('3d_chunked', 3, [32, 16, 16], [8, 8, 8], [-1.0_wp, 0.25_wp, 3.0_wp], &
    [2.0_wp, 1.5_wp, 4.0_wp], [6, 11], .true., [8, 8, 8])
  call run_case('3d_chunked_uneven', 3, [98, 16, 8], [8, 8, 8], [-1.0_wp, 0.25_wp, 3.0_wp], &
    [2.0_wp, 1.5_wp, 4.0_wp], [integer ::], .false., [8, 8, 8])

  call h5_finalize()
  call check_done()

contains

  !> The value stored at global cell (gi, gj, gk) of field m: irrational bits everywhere.
  pure real(wp) function known_value(gi, gj, gk, m)
    integer, intent(in) :: gi, gj, gk, m
    known_value = real(m, wp) * 1000.0_wp + real(gi, wp) / 3.0_wp + &
      real(gj, wp) * sqrt(2.0_wp) - real(gk, wp) * 1.0e-7_wp / 7.0_wp
  end function known_value

  elemental logical function same_bits(a, b)
    real(wp), intent(in) :: a, b
    same_bits = transfer(a, 0_i8) == transfer(b, 0_i8)
  end function same_bits

  !> The ids (ascending) of the blocks whose owner is this rank.
  subroutine my_blocks(lay, ids)
    type(layout_t), intent(in) :: lay
    integer, allocatable, intent(out) :: ids(:)
    integer :: id
    allocate(ids(0))
    do id = 1, lay%nblocks
      if (lay%owner(id) == comm_rank()) ids = [ids, id]
    end do
  end subroutine my_blocks

  subroutine run_case(tag, ndim, cells, bsize, lo, hi, inactive, leave_last_rank_empty, chunk)
    character(len=*), intent(in) :: tag
    integer, intent(in) :: ndim, cells(3), bsize(3), inactive(:), chunk(3)
    real(wp), intent(in) :: lo(3), hi(3)
    logical, intent(in) :: leave_last_rank_empty
    type(layout_t) :: lay
    type(h5_file_t) :: f
    character(len=:), allocatable :: path, deck, text
    integer, allocatable :: ids(:)
    real(wp), allocatable :: data(:, :, :, :)
    integer :: n_writers, n_active, id, k, m, step, cells_read(3), ndim_read
    real(wp) :: time, lohi(3), coeffs(4)
    character(len=64) :: title, empty

    path = 'test_hdf5_' // tag // '.h5'
    call layout_init(lay, ndim, cells, bsize, lo, hi, [.false., .false., .false.], .false.)
    lay%active(inactive) = .false.
    n_active = count(lay%active)

    ! Write: active blocks dealt round-robin, optionally leaving the last rank empty.
    n_writers = comm_size()
    if (leave_last_rank_empty .and. comm_size() > 1) n_writers = comm_size() - 1
    k = 0
    do id = 1, lay%nblocks
      lay%owner(id) = -1
      if (.not. lay%active(id)) cycle
      lay%owner(id) = mod(k, n_writers)
      k = k + 1
    end do
    call my_blocks(lay, ids)
    allocate(data(lay%nmax(1), lay%nmax(2), lay%nmax(3), size(ids)))

    ! Rank 0's deck and title are what the file must hold; the other ranks pass junk.
    deck = ''
    do k = 1, 2000
      deck = deck // '  key_' // int_text(k) // ' = ' // int_text(7 * k) // new_line('a')
    end do
    deck = '&run' // new_line('a') // deck // '/' // new_line('a')
    title = 'SABRE unit test ' // tag
    if (.not. comm_is_root()) then
      deck = 'not rank 0'
      title = 'wrong'
    end if
    time = 1.0_wp / 3.0_wp
    coeffs = [1.0_wp / 7.0_wp, -0.0_wp, huge(1.0_wp), tiny(1.0_wp)]

    call h5_create(f, path, lay)
    do m = 1, n_fields
      call fill_known(lay, ids, m, data)
      call h5_write_field(f, trim(field_path(m)), lay, ids, data)
    end do
    call h5_write_attr(f, 'time', time)
    call h5_write_attr(f, 'step', 4242)
    call h5_write_attr(f, 'coeffs', coeffs)
    call h5_write_attr(f, 'title', title)
    call h5_write_attr(f, 'empty', '')
    call h5_write_attr(f, 'step', 17)   ! replaces the first one
    call h5_write_text(f, '/input/deck', deck)
    call h5_write_text(f, '/input/blank', '')
    call h5_close(f)
    call xdmf_write('test_hdf5_' // tag // '.xmf', path, lay, ['rho', 'p  '], time)
    if (comm_is_root()) call check_xdmf(tag)
    if (comm_is_root()) call check_chunks(tag, path, chunk)

    ! Read back into the blocks of another owner assignment: active blocks in contiguous
    ! chunks, in reverse rank order; rank 0 also asks for the inactive blocks.
    k = 0
    do id = 1, lay%nblocks
      if (.not. lay%active(id)) cycle
      lay%owner(id) = comm_size() - 1 - (k * comm_size()) / n_active
      k = k + 1
    end do
    call my_blocks(lay, ids)
    if (comm_is_root()) ids = [ids, inactive]
    deallocate(data)
    allocate(data(lay%nmax(1), lay%nmax(2), lay%nmax(3), size(ids)))

    call h5_open_read(f, path)
    do m = 1, n_fields
      data = -1.0_wp
      call h5_read_field(f, trim(field_path(m)), lay, ids, data)
      call check_known(tag, lay, ids, m, data)
    end do

    call h5_read_attr(f, 'time', time)
    call check(tag // ': attribute time', same_bits(time, 1.0_wp / 3.0_wp))
    call h5_read_attr(f, 'step', step)
    call check(tag // ': attribute step ' // int_text(step), step == 17)
    coeffs = 0.0_wp
    call h5_read_attr(f, 'coeffs', coeffs)
    call check(tag // ': attribute coeffs', all(same_bits(coeffs, [1.0_wp / 7.0_wp, -0.0_wp, &
      huge(1.0_wp), tiny(1.0_wp)])))
    call h5_read_attr(f, 'title', title)
    call check(tag // ': attribute title "' // trim(title) // '"', &
      title == 'SABRE unit test ' // tag)
    empty = 'x'
    call h5_read_attr(f, 'empty', empty)
    call check(tag // ': attribute empty "' // trim(empty) // '"', empty == '')
    call h5_read_attr(f, 'cells', cells_read)
    call check(tag // ': attribute cells', all(cells_read == lay%cells))
    call h5_read_attr(f, 'ndim', ndim_read)
    call check(tag // ': attribute ndim', ndim_read == ndim)
    call h5_read_attr(f, 'lo', lohi)
    call check(tag // ': attribute lo', all(same_bits(lohi, lay%lo)))
    call h5_read_attr(f, 'hi', lohi)
    call check(tag // ': attribute hi', all(same_bits(lohi, lay%hi)))

    call h5_read_text(f, '/input/deck', text)
    if (comm_is_root()) then
      call check(tag // ': text /input/deck', text == deck .and. &
        len(text) == len(deck))
    else
      call check(tag // ': text /input/deck is not rank 0''s', len(text) >= 30000)
    end if
    call h5_read_text(f, '/input/blank', text)
    call check(tag // ': text /input/blank not empty', len(text) == 0)

    call check(tag // ': /fields/rho not found', h5_exists(f, '/fields/rho'))
    call check(tag // ': state/deep not found', h5_exists(f, 'state/deep'))
    call check(tag // ': /fields/none found', .not. h5_exists(f, '/fields/none'))
    call check(tag // ': /nogroup/x/y found', .not. h5_exists(f, '/nogroup/x/y'))
    call check(tag // ': attribute coeffs not found', h5_has_attr(f, 'coeffs'))
    call check(tag // ': attribute fix_crossing found', .not. h5_has_attr(f, 'fix_crossing'))
    call h5_close(f)

    call comm_barrier()
    if (.not. keep .and. comm_is_root()) then
      call delete_file(path)
      call delete_file('test_hdf5_' // tag // '.xmf')
    end if
  end subroutine run_case

  subroutine fill_known(lay, ids, m, data)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:), m
    real(wp), intent(out) :: data(:, :, :, :)
    integer :: k, i, j, l, off(3), n(3)
    data = 0.0_wp
    do k = 1, size(ids)
      off = block_offset(lay, ids(k))
      n = block_extent(lay, ids(k))
      do l = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            data(i, j, l, k) = known_value(off(1) + i, off(2) + j, off(3) + l, m)
          end do
        end do
      end do
    end do
  end subroutine fill_known

  subroutine check_known(tag, lay, ids, m, data)
    character(len=*), intent(in) :: tag
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ids(:), m
    real(wp), intent(in) :: data(:, :, :, :)
    real(wp) :: want(size(data, 1), size(data, 2), size(data, 3), size(data, 4))
    integer :: k, i, j, l, n(3), nbad
    character(len=160) :: msg
    ! what was written (fill_known), an inactive block reading back as 0
    call fill_known(lay, ids, m, want)
    nbad = 0
    msg = ''
    do k = 1, size(ids)
      if (.not. lay%active(ids(k))) want(:, :, :, k) = 0.0_wp
      n = block_extent(lay, ids(k))
      do l = 1, n(3)
        do j = 1, n(2)
          do i = 1, n(1)
            if (same_bits(data(i, j, l, k), want(i, j, l, k))) cycle
            nbad = nbad + 1
            if (nbad == 1) write(msg, '(a, i0, a, 3(i0, 1x), a, es24.16, a, es24.16)') &
              ', first: block ', ids(k), ' cell ', block_offset(lay, ids(k)) + [i, j, l], &
              'read ', data(i, j, l, k), ' want ', want(i, j, l, k)
          end do
        end do
      end do
    end do
    call check(tag // ': field ' // trim(field_path(m)) // ' read back bit for bit (' // &
      int_text(nbad) // ' cells differ' // trim(msg) // ')', nbad == 0)
  end subroutine check_known

  !> The mesh of the .xmf: nodes, origin and spacing in z, y, x order, a 2D (1D) layout flat
  !> (one node, at 0, spacing dx(1)) along its unused directions, numbers in the fewest
  !> digits that read back (m_xdmf).
  subroutine check_xdmf(tag)
    character(len=*), intent(in) :: tag
    character(len=:), allocatable :: nodes, origin, spacing
    character(len=256) :: line, prev
    integer :: u, ios, found
    select case (tag)
    case ('1d')
      nodes = '1 1 65'
      origin = '0.0 0.0 -1.0'
      spacing = '0.046875 0.046875 0.046875'
    case ('2d')
      nodes = '1 17 25'
      origin = '0.0 0.25 -1.0'
      spacing = '0.125 0.078125 0.125'
    case ('2d_uneven')
      nodes = '1 19 31'
      origin = '0.0 0.25 -1.0'
      spacing = '0.1 0.06944444444444445 0.1'
    case ('3d')
      nodes = '17 9 13'
      origin = '3.0 0.25 -1.0'
      spacing = '0.0625 0.15625 0.25'
    case default
      return
    end select
    open(newunit=u, file='test_hdf5_' // tag // '.xmf', status='old', action='read', &
      iostat=ios)
    call check(tag // ': read test_hdf5_' // tag // '.xmf', ios == 0)
    if (ios /= 0) return
    found = 0
    prev = ''
    do
      read(u, '(a)', iostat=ios) line
      if (ios /= 0) exit
      if (index(line, 'TopologyType="3DCoRectMesh" Dimensions="' // nodes // '"') > 0) &
        found = found + 1
      if (index(prev, 'Name="Origin"') > 0 .and. trim(adjustl(line)) == origin) &
        found = found + 1
      if (index(prev, 'Name="Spacing"') > 0 .and. trim(adjustl(line)) == spacing) &
        found = found + 1
      prev = line
    end do
    close(u)
    call check(tag // ': .xmf mesh is nodes "' // nodes // '", origin "' // origin // &
      '", spacing "' // spacing // '"', found == 3)
  end subroutine check_xdmf

  !> The storage of /fields/rho in path: chunks of chunk cells (Fortran order), or contiguous
  !> for chunk 0, read with the serial HDF5 library on rank 0 after the file is closed.
  subroutine check_chunks(tag, path, chunk)
    character(len=*), intent(in) :: tag, path
    integer, intent(in) :: chunk(3)
    integer(hid_t) :: fid, dset, dcpl
    integer(hsize_t) :: dims(3)
    integer :: layout, err, nd
    call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, err)
    call h5dopen_f(fid, '/fields/rho', dset, err)
    call h5dget_create_plist_f(dset, dcpl, err)
    call h5pget_layout_f(dcpl, layout, err)
    dims = 0
    if (layout == H5D_CHUNKED_F) call h5pget_chunk_f(dcpl, 3, dims, nd)
    call h5pclose_f(dcpl, err)
    call h5dclose_f(dset, err)
    call h5fclose_f(fid, err)
    call check(tag // ': /fields/rho stored in chunks of ' // int_text(int(dims(1))) // &
      'x' // int_text(int(dims(2))) // 'x' // int_text(int(dims(3))) // ', want ' // &
      int_text(chunk(1)) // 'x' // int_text(chunk(2)) // 'x' // int_text(chunk(3)), &
      all(dims == int(chunk, hsize_t)))
  end subroutine check_chunks

  subroutine delete_file(path)
    character(len=*), intent(in) :: path
    integer :: u, ios
    open(newunit=u, file=path, status='old', iostat=ios)
    if (ios == 0) close(u, status='delete')
  end subroutine delete_file

end program test_hdf5
