!> All inter-rank communication of SABRE (DESIGN section 3): start and stop, rank and size,
!> min/max/sum reductions, broadcasts, barrier, abort, and the exchange of packed halo
!> buffers between partner ranks. This module is what the rest of the code uses; the
!> transport is m_comm_backend, of which the Makefile compiles one: m_comm_mpi.f90 (MPI
!> point-to-point and collectives, the default) or m_comm_caf.f90 (`make COMM=caf`:
!> coarray puts, `sync images` and the collective subroutines of Fortran 2018). Both give
!> bit-identical fields. Nothing here knows of physics or blocks; ranks count from 0 (an
!> image is rank + 1).
module m_comm
  use, intrinsic :: iso_c_binding, only: c_int
  use m_kinds, only: wp, i8
  ! both back ends run on MPI (OpenCoarrays too): the world handles for parallel HDF5, the
  ! wall clock and the node's ranks come from it whichever back end moves the halos
  use mpi_f08, only: MPI_Comm, MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, MPI_INFO_NULL, &
    MPI_Comm_split_type, MPI_Comm_size, MPI_Comm_rank, MPI_Comm_free, MPI_Wtime
  use m_comm_backend, only: comm_backend_name, backend_init, backend_finalize, &
    backend_barrier, backend_max, backend_sum_real, backend_sum_int8, &
    backend_bcast_int, backend_bcast_real, backend_bcast_logical, backend_bcast_chars, &
    backend_abort, comm_exchange_t, exchange_setup, exchange_start, &
    backend_exchange_wait => exchange_wait
  implicit none
  private
  public :: comm_init, comm_finalize, comm_rank, comm_size, comm_is_root, comm_barrier
  public :: comm_min, comm_max, comm_sum, comm_sum_array, comm_sum_by_key, comm_any
  public :: comm_minloc_rank
  public :: comm_bcast, comm_abort, comm_exit, comm_wtime, comm_world_handles, comm_node_ranks
  public :: comm_backend_name, comm_wait_seconds
  public :: comm_exchange_t, exchange_setup, exchange_start, exchange_wait

  integer :: my_rank = 0
  integer :: n_ranks = 1
  !> processor seconds this process spent in the blocking calls (halo waits, reductions)
  !> since it started: a clock that only runs while waiting; its users take differences
  !> (m_rebalance: the rank's own work is its processor time less this)
  real(wp) :: waiting = 0.0_wp

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
    module procedure comm_bcast_string, comm_bcast_int, backend_bcast_int, &
      backend_bcast_real, backend_bcast_logical
  end interface comm_bcast

  interface
    subroutine c_exit(status) bind(C, name='exit')
      import :: c_int
      integer(c_int), value :: status
    end subroutine c_exit
  end interface

contains

  subroutine comm_init()
    call backend_init(my_rank, n_ranks)
  end subroutine comm_init

  subroutine comm_finalize()
    call backend_finalize()
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
    call backend_barrier()
  end subroutine comm_barrier

  !> The integer (pre-mpi_f08) handles of the world communicator and the null info object,
  !> for libraries with an MPI interface of their own (parallel HDF5). The coarray build
  !> runs on MPI too (OpenCoarrays), so both back ends have them.
  subroutine comm_world_handles(comm, info)
    integer, intent(out) :: comm, info
    comm = MPI_COMM_WORLD%mpi_val
    info = MPI_INFO_NULL%mpi_val
  end subroutine comm_world_handles

  !> The ranks that share this rank's node (its shared-memory domain), and whether this
  !> rank is the lowest of them: the one that speaks for the node's memory. MPI in both
  !> builds (the coarray build runs on Open MPI).
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

  !> Processor seconds spent waiting in blocking calls so far (a clock: take differences).
  real(wp) function comm_wait_seconds()
    comm_wait_seconds = waiting
  end function comm_wait_seconds

  !> Add the processor time since t0 (cpu_time) to the waiting clock.
  subroutine waited(t0)
    real(wp), intent(in) :: t0
    real(wp) :: t
    call cpu_time(t)
    waiting = waiting + (t - t0)
  end subroutine waited

  !> The halo exchange's wait, timed for the waiting clock.
  subroutine exchange_wait(ex, recvbuf)
    type(comm_exchange_t), intent(inout) :: ex
    real(wp), intent(inout), asynchronous :: recvbuf(:, :)
    real(wp) :: t0
    call cpu_time(t0)
    call backend_exchange_wait(ex, recvbuf)
    call waited(t0)
  end subroutine exchange_wait

  !> The one real max of the back end, timed; min and the integers come from it: negation
  !> is exact, and so is a 32-bit integer as a double.
  real(wp) function comm_max_real(x) result(r)
    real(wp), intent(in) :: x
    real(wp) :: t0
    call cpu_time(t0)
    r = backend_max(x)
    call waited(t0)
  end function comm_max_real

  real(wp) function comm_min_real(x) result(r)
    real(wp), intent(in) :: x
    r = -comm_max_real(-x)
  end function comm_min_real

  integer function comm_max_int(x) result(r)
    integer, intent(in) :: x
    r = nint(comm_max_real(real(x, wp)))
  end function comm_max_int

  integer(i8) function comm_sum_int8(x) result(r)
    integer(i8), intent(in) :: x
    real(wp) :: t0
    call cpu_time(t0)
    r = backend_sum_int8(x)
    call waited(t0)
  end function comm_sum_int8

  !> the back end's real sum, timed
  subroutine sum_real(x)
    real(wp), intent(inout) :: x(:)
    real(wp) :: t0
    call cpu_time(t0)
    call backend_sum_real(x)
    call waited(t0)
  end subroutine sum_real

  integer function comm_min_int(x) result(r)
    integer, intent(in) :: x
    r = -comm_max_int(-x)
  end function comm_min_int

  !> Sums are for diagnostics: their last bits depend on the number of ranks (a sum that
  !> steers the solution adds one non-zero term per entry, which any order gives exactly).
  real(wp) function comm_sum_real(x) result(r)
    real(wp), intent(in) :: x
    real(wp) :: v(1)
    v(1) = x
    call sum_real(v)
    r = v(1)
  end function comm_sum_real

  subroutine comm_sum_array(x)
    real(wp), intent(inout) :: x(:)
    call sum_real(x)
  end subroutine comm_sum_array

  !> The sum over keys 1..nkey, in key order, of the columns part(:, m) with key(m) = that
  !> key, each key held by one column on one rank (a block's partial sums, key = its id):
  !> the same bits however the keys are spread over the ranks, since each entry of the
  !> rank sum has one non-zero term. A sum that must not depend on the partition (history,
  !> which a re-partitioned run keeps byte for byte) goes through here.
  function comm_sum_by_key(part, key, nkey) result(total)
    real(wp), intent(in) :: part(:, :)
    integer, intent(in) :: key(:), nkey
    real(wp) :: total(size(part, 1))
    real(wp), allocatable :: flat(:)
    integer :: m, nv, k
    nv = size(part, 1)
    allocate(flat(nv * nkey))
    flat = 0.0_wp
    do m = 1, size(part, 2)
      flat(nv * (key(m) - 1) + 1:nv * key(m)) = part(:, m)
    end do
    call sum_real(flat)
    total = 0.0_wp
    do k = 1, nkey
      total = total + flat(nv * (k - 1) + 1:nv * k)
    end do
  end function comm_sum_by_key

  logical function comm_any(x) result(r)
    logical, intent(in) :: x
    r = comm_max_int(merge(1, 0, x)) > 0
  end function comm_any

  !> The lowest rank for which flag is true, or -1 when no rank has it.
  integer function comm_minloc_rank(flag) result(r)
    logical, intent(in) :: flag
    integer :: mine
    mine = huge(1)
    if (flag) mine = my_rank
    r = comm_min_int(mine)
    if (r == huge(1)) r = -1
  end function comm_minloc_rank

  !> Broadcast a deferred-length string from root to every rank.
  subroutine comm_bcast_string(text, root)
    character(len=:), allocatable, intent(inout) :: text
    integer, intent(in) :: root
    integer :: n
    n = 0
    if (my_rank == root) n = len(text)
    call comm_bcast_int(n, root)
    if (my_rank /= root) then
      if (allocated(text)) deallocate(text)
      allocate(character(len=n) :: text)
    end if
    if (n > 0) call backend_bcast_chars(text, root)
  end subroutine comm_bcast_string

  subroutine comm_bcast_int(x, root)
    integer, intent(inout) :: x
    integer, intent(in) :: root
    integer :: v(1)
    v(1) = x
    call backend_bcast_int(v, root)
    x = v(1)
  end subroutine comm_bcast_int

  !> Stop every rank at once with a non-zero exit status (an error seen by one rank only).
  subroutine comm_abort(code)
    integer, intent(in) :: code
    flush(6)
    flush(0)
    call backend_abort(code)
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

end module m_comm
