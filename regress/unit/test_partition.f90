!> Unit test of m_partition (METIS on the graph of active blocks) on any number of ranks,
!> for a 1D row, a 2D and a 3D layout, with and without inactive (obstacle) blocks and with
!> uniform and uneven work: every active block gets exactly one owner in 0..ranks-1 and
!> every rank at least one block; inactive blocks are left out (owner -1); every rank holds
!> the same map; a second partition of the same layout gives the same map (deterministic);
!> and the work is balanced: the largest rank's work is at most (1 + tol) times the mean
!> plus one block's work (tol 0.05; METIS's default allows 3 % imbalance, and a rank can only
!> take whole blocks).
program test_partition
  use m_kinds, only: wp
  use m_layout, only: layout_t, layout_init
  use m_partition, only: partition_blocks
  use m_comm, only: comm_init, comm_size, comm_sum_array, comm_is_root
  use m_test_check, only: check_start, check, check_done, int_text
  implicit none
  real(wp), parameter :: tol = 0.05_wp
  call comm_init()
  call check_start('test_partition')
  call run_case('1d row', 1, [256, 1, 1], [8, 1, 1], [integer ::], .false.)
  call run_case('2d uniform', 2, [64, 64, 1], [8, 8, 1], [integer ::], .false.)
  call run_case('2d holes', 2, [64, 64, 1], [8, 8, 1], [10, 11, 18, 19, 46], .false.)
  call run_case('2d uneven work', 2, [64, 32, 1], [8, 8, 1], [integer ::], .true.)
  call run_case('3d uniform', 3, [32, 32, 32], [8, 8, 8], [integer ::], .false.)
  call run_case('3d holes, uneven work', 3, [32, 32, 32], [8, 8, 8], [1, 22, 43, 64], .true.)
  call check_done()

contains

  subroutine run_case(tag, ndim, cells, bsize, holes, uneven)
    character(len=*), intent(in) :: tag
    integer, intent(in) :: ndim, cells(3), bsize(3), holes(:)
    logical, intent(in) :: uneven
    type(layout_t) :: lay
    integer, allocatable :: work(:), first(:)
    real(wp), allocatable :: owner_sum(:)
    real(wp), allocatable :: load(:)
    real(wp) :: mean
    integer :: id, r, nranks
    real(wp), parameter :: lo(3) = 0.0_wp, hi(3) = 1.0_wp
    nranks = comm_size()
    call layout_init(lay, ndim, cells, bsize, lo, hi, [.false., .false., .false.], .false.)
    lay%active(holes) = .false.
    allocate(work(lay%nblocks))
    ! uneven: the blocks of the first third by id cost 4 times the others (a heavy region)
    work = 1
    if (uneven) where ([(id <= lay%nblocks / 3, id = 1, lay%nblocks)]) work = 4
    call partition_blocks(lay, work)
    first = lay%owner

    call check(tag // ': every active block has an owner in 0..ranks-1', &
      all(pack(lay%owner, lay%active) >= 0 .and. pack(lay%owner, lay%active) < nranks))
    call check(tag // ': inactive blocks have no owner (-1)', &
      all(pack(lay%owner, .not. lay%active) == -1))
    allocate(load(0:nranks - 1))
    load = 0.0_wp
    do id = 1, lay%nblocks
      if (lay%active(id) .and. lay%owner(id) >= 0 .and. lay%owner(id) < nranks) &
        load(lay%owner(id)) = load(lay%owner(id)) + work(id)
    end do
    do r = 0, nranks - 1
      call check(tag // ': rank ' // int_text(r) // ' owns at least one block', &
        any(lay%owner == r))
    end do
    mean = sum(work, mask=lay%active) / real(nranks, wp)
    if (comm_is_root()) write(6, '(a,f8.1,a,f8.1,a,f6.3)') tag // ': work per rank largest ', &
      maxval(load), ', mean ', mean, ', ratio ', maxval(load) / mean
    call check(tag // ': largest work ' // int_text(nint(maxval(load))) // ' within ' // &
      '(1 + tol) mean + one block, mean ' // int_text(nint(mean)), &
      maxval(load) <= (1.0_wp + tol) * mean + maxval(work, mask=lay%active))
    call check(tag // ': the work of all ranks is the work of the active blocks', &
      nint(sum(load)) == sum(work, mask=lay%active))

    ! every rank holds the same map: the sum over ranks of each owner is ranks times it
    owner_sum = real(lay%owner, wp)
    call comm_sum_array(owner_sum)
    call check(tag // ': every rank holds the same owner map', &
      all(nint(owner_sum) == nranks * lay%owner))

    call partition_blocks(lay, work)
    call check(tag // ': a second partition gives the same map', all(lay%owner == first))
  end subroutine run_case

end program test_partition
