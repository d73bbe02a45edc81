!> All inter-rank communication of SABRE (DESIGN section 3): start and stop, rank and size,
!> min/max/sum reductions, broadcasts, barrier, abort, and the nonblocking point-to-point
!> exchange of packed halo buffers. This is the MPI back end; nothing else in the code
!> calls MPI. The module knows nothing of physics or of blocks.
module m_comm
  use, intrinsic :: iso_c_binding, only: c_int
  use mpi_f08
  use m_kinds, only: wp, i8
  implicit none
  private
  public :: comm_init, comm_finalize, comm_rank, comm_size, comm_is_root, comm_barrier
  public :: comm_min, comm_max, comm_sum, comm_sum_array, comm_any, comm_minloc_rank
  public :: comm_bcast, comm_abort, comm_exit, comm_wtime, comm_world_handles, comm_node_ranks
  public :: comm_exchange_t, exchange_start, exchange_wait

  integer :: my_rank = 0
  integer :: n_ranks = 1

  !> A set of messages, one per partner rank, exchanged with nonblocking sends/receives.
  type :: comm_exchange_t
    integer :: n = 0
    integer, allocatable :: partner(:)
    type(MPI_Request), allocatable :: req(:)
  end type comm_exchange_t

  interface comm_min
    module procedure comm_min_real, comm_min_int
  end interface comm_min
  interface comm_max
    module procedure comm_max_real, comm_max_int
  end interface comm_max
  interface comm_sum
    module procedure comm_sum_real, comm_sum_int8
  end interface comm_sum
  interface comm_bcast
    module procedure comm_bcast_string, comm_bcast_int, comm_bcast_int_array, &
      comm_bcast_real, comm_bcast_logical
  end interface comm_bcast

  interface
    subroutine c_exit(status) bind(C, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
  end interface

contains

  subroutine comm_init()
    integer :: ierr
    logical :: started
    call MPI_Initialized(started, ierr)
    if (.not. started) call MPI_Init(ierr)
    call MPI_Comm_rank(MPI_COMM_WORLD, my_rank, ierr)
    call MPI_Comm_size(MPI_COMM_WORLD, n_ranks, ierr)
  end subroutine comm_init

  subroutine comm_finalize()
    integer :: ierr
    logical :: done
    call MPI_Finalized(done, ierr)
    if (.not. done) call MPI_Finalize(ierr)
  end subroutine comm_finalize

  integer function comm_rank()
    comm_rank = my_rank
  end function comm_rank

  integer function comm_size()
    comm_size = n_ranks
  end function comm_size

  logical function comm_is_root()
    comm_is_root = (my_rank == 0)
  end function comm_is_root

  subroutine comm_barrier()
    integer :: ierr
    call MPI_Barrier(MPI_COMM_WORLD, ierr)
  end subroutine comm_barrier

  !> The integer (pre-mpi_f08) handles of the world communicator and the null info object,
  !> for libraries with an MPI interface of their own (parallel HDF5).
  subroutine comm_world_handles(comm, info)
    integer, intent(out) :: comm, info
    comm = MPI_COMM_WORLD%mpi_val
    info = MPI_INFO_NULL%mpi_val
  end subroutine comm_world_handles

  !> The ranks that share this rank's node (its shared-memory domain), and whether this
  !> rank is the lowest of them: the one that speaks for the node's memory.
  subroutine comm_node_ranks(n, leader)
    integer, intent(out) :: n
    logical, intent(out) :: leader
    type(MPI_Comm) :: node
    integer :: me, ierr
    call MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, my_rank, MPI_INFO_NULL, &
      node, ierr)
    call MPI_Comm_size(node, n, ierr)
    call MPI_Comm_rank(node, me, ierr)
    leader = (me == 0)
    call MPI_Comm_free(node, ierr)
  end subroutine comm_node_ranks

  real(wp) function comm_wtime()
    comm_wtime = MPI_Wtime()
  end function comm_wtime

  real(wp) function comm_min_real(x) result(r)
    real(wp), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_DOUBLE_PRECISION, MPI_MIN, MPI_COMM_WORLD, ierr)
  end function comm_min_real

  integer function comm_min_int(x) result(r)
    integer, intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD, ierr)
  end function comm_min_int

  real(wp) function comm_max_real(x) result(r)
    real(wp), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  end function comm_max_real

  integer function comm_max_int(x) result(r)
    integer, intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD, ierr)
  end function comm_max_int

  !> Sums are for diagnostics only: their last bits depend on the number of ranks.
  real(wp) function comm_sum_real(x) result(r)
    real(wp), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD, ierr)
  end function comm_sum_real

  subroutine comm_sum_array(x)
    real(wp), intent(inout) :: x(:)
    real(wp) :: r(size(x))
    integer :: ierr
    call MPI_Allreduce(x, r, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD, ierr)
    x = r
  end subroutine comm_sum_array

  integer(i8) function comm_sum_int8(x) result(r)
    integer(i8), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_INTEGER8, MPI_SUM, MPI_COMM_WORLD, ierr)
  end function comm_sum_int8

  logical function comm_any(x) result(r)
    logical, intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_LOGICAL, MPI_LOR, MPI_COMM_WORLD, ierr)
  end function comm_any

  !> The lowest rank for which flag is true, or -1 when no rank has it.
  integer function comm_minloc_rank(flag) result(r)
    logical, intent(in) :: flag
    integer :: mine, ierr
    mine = huge(1)
    if (flag) mine = my_rank
    call MPI_Allreduce(mine, r, 1, MPI_INTEGER, MPI_MIN, MPI_COMM_WORLD, ierr)
    if (r == huge(1)) r = -1
  end function comm_minloc_rank

  !> Broadcast a deferred-length string from root to every rank.
  subroutine comm_bcast_string(text, root)
    character(len=:), allocatable, intent(inout) :: text
    integer, intent(in) :: root
    integer :: n, ierr
    n = 0
    if (my_rank == root) n = len(text)
    call MPI_Bcast(n, 1, MPI_INTEGER, root, MPI_COMM_WORLD, ierr)
    if (my_rank /= root) then
      if (allocated(text)) deallocate(text)
      allocate(character(len=n) :: text)
    end if
    if (n > 0) call MPI_Bcast(text, n, MPI_CHARACTER, root, MPI_COMM_WORLD, ierr)
  end subroutine comm_bcast_string

  subroutine comm_bcast_int(x, root)
    integer, intent(inout) :: x
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, 1, MPI_INTEGER, root, MPI_COMM_WORLD, ierr)
  end subroutine comm_bcast_int

  subroutine comm_bcast_int_array(x, root)
    integer, intent(inout) :: x(:)
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, size(x), MPI_INTEGER, root, MPI_COMM_WORLD, ierr)
  end subroutine comm_bcast_int_array

  subroutine comm_bcast_real(x, root)
    real(wp), intent(inout) :: x
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, 1, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD, ierr)
  end subroutine comm_bcast_real

  subroutine comm_bcast_logical(x, root)
    logical, intent(inout) :: x
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, 1, MPI_LOGICAL, root, MPI_COMM_WORLD, ierr)
  end subroutine comm_bcast_logical

  !> Stop every rank at once with a non-zero exit status (an error seen by one rank only).
  subroutine comm_abort(code)
    integer, intent(in) :: code
    integer :: ierr
    flush(6)
    flush(0)
    call MPI_Abort(MPI_COMM_WORLD, code, ierr)
    call c_exit(int(code, c_int))
  end subroutine comm_abort

  !> Leave cleanly with the given exit status; every rank must call it.
  subroutine comm_exit(code)
    integer, intent(in) :: code
    flush(6)
    flush(0)
    call comm_finalize()
    call c_exit(int(code, c_int))
  end subroutine comm_exit

  !> Start one exchange: post a receive and a send of one packed buffer per partner.
  !> sendbuf(:, m) / recvbuf(:, m) hold the message for partner(m); counts give lengths.
  subroutine exchange_start(ex, partner, sendbuf, scount, recvbuf, rcount)
    type(comm_exchange_t), intent(inout) :: ex
    integer, intent(in) :: partner(:), scount(:), rcount(:)
    real(wp), intent(in), asynchronous :: sendbuf(:, :)
    real(wp), intent(inout), asynchronous :: recvbuf(:, :)
    integer :: m, ierr
    integer, parameter :: tag = 4242
    ex%n = size(partner)
    if (allocated(ex%req)) then
      if (size(ex%req) < 2 * ex%n) deallocate(ex%req)
    end if
    if (.not. allocated(ex%req)) allocate(ex%req(max(1, 2 * ex%n)))
    do m = 1, ex%n
      call MPI_Irecv(recvbuf(:, m), rcount(m), MPI_DOUBLE_PRECISION, partner(m), tag, &
        MPI_COMM_WORLD, ex%req(m), ierr)
    end do
    do m = 1, ex%n
      call MPI_Isend(sendbuf(:, m), scount(m), MPI_DOUBLE_PRECISION, partner(m), tag, &
        MPI_COMM_WORLD, ex%req(ex%n + m), ierr)
    end do
  end subroutine exchange_start

  subroutine exchange_wait(ex)
    type(comm_exchange_t), intent(inout) :: ex
    integer :: ierr
    if (ex%n > 0) call MPI_Waitall(2 * ex%n, ex%req, MPI_STATUSES_IGNORE, ierr)
    ex%n = 0
  end subroutine exchange_wait

end module m_comm
