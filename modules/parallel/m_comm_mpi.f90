!> The MPI back end of m_comm (DESIGN section 3), compiled by the default build
!> (COMM=mpi): collectives on MPI_COMM_WORLD and the halo exchange as one nonblocking
!> send and receive per partner rank. Only m_comm uses it; m_comm_caf.f90 is the coarray
!> back end with the same interface. Ranks count from 0.
module m_comm_backend
  use mpi_f08
  use m_kinds, only: wp, i8
  implicit none
  private
  include 'm_comm_backend.inc'

  character(len=*), parameter :: comm_backend_name = 'MPI'

  !> A set of messages, one per partner rank, exchanged with nonblocking sends/receives.
  type :: comm_exchange_t
    integer :: n = 0
    type(MPI_Request), allocatable :: req(:)
  end type comm_exchange_t

contains

  subroutine backend_init(rank, nranks)
    integer, intent(out) :: rank, nranks
    integer :: ierr
    logical :: started
    call MPI_Initialized(started, ierr)
    if (.not. started) call MPI_Init(ierr)
    call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
    call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  end subroutine backend_init

  subroutine backend_finalize()
    integer :: ierr
    logical :: done
    call MPI_Finalized(done, ierr)
    if (.not. done) call MPI_Finalize(ierr)
  end subroutine backend_finalize

  subroutine backend_barrier()
    integer :: ierr
    call MPI_Barrier(MPI_COMM_WORLD, ierr)
  end subroutine backend_barrier

  subroutine backend_abort(code)
    integer, intent(in) :: code
    integer :: ierr
    call MPI_Abort(MPI_COMM_WORLD, code, ierr)
  end subroutine backend_abort

  !> The largest x over the ranks (exact in any order); m_comm makes min and the integer
  !> versions of it (every 32-bit integer is a double exactly).
  real(wp) function backend_max(x) result(r)
    real(wp), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  end function backend_max

  subroutine backend_sum_real(x)
    real(wp), intent(inout) :: x(:)
    real(wp) :: r(size(x))
    integer :: ierr
    call MPI_Allreduce(x, r, size(x), MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD, ierr)
    x = r
  end subroutine backend_sum_real

  integer(i8) function backend_sum_int8(x) result(r)
    integer(i8), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, r, 1, MPI_INTEGER8, MPI_SUM, MPI_COMM_WORLD, ierr)
  end function backend_sum_int8

  subroutine backend_bcast_chars(text, root)
    character(len=*), intent(inout) :: text
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(text, len(text), MPI_CHARACTER, root, MPI_COMM_WORLD, ierr)
  end subroutine backend_bcast_chars

  subroutine backend_bcast_int(x, root)
    integer, intent(inout) :: x(:)
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, size(x), MPI_INTEGER, root, MPI_COMM_WORLD, ierr)
  end subroutine backend_bcast_int

  subroutine backend_bcast_real(x, root)
    real(wp), intent(inout) :: x
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, 1, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD, ierr)
  end subroutine backend_bcast_real

  subroutine backend_bcast_logical(x, root)
    logical, intent(inout) :: x
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(x, 1, MPI_LOGICAL, root, MPI_COMM_WORLD, ierr)
  end subroutine backend_bcast_logical

  !> Collective: every rank calls it once per plan, before that plan's first exchange.
  !> MPI needs no set-up beyond the request list; capacity (the largest message from each
  !> partner) matters to the coarray back end only.
  subroutine exchange_setup(ex, partner, capacity)
    type(comm_exchange_t), intent(inout) :: ex
    integer, intent(in) :: partner(:), capacity(:)
    if (size(capacity) /= size(partner)) call internal_error('exchange_setup', &
      'one capacity per partner')
    ex%n = 0
    if (allocated(ex%req)) deallocate(ex%req)
    allocate(ex%req(max(1, 2 * size(partner))))
  end subroutine exchange_setup

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

  !> Complete the exchange: recvbuf (the array given to exchange_start) holds every
  !> partner's message on return.
  subroutine exchange_wait(ex, recvbuf)
    type(comm_exchange_t), intent(inout) :: ex
    real(wp), intent(inout), asynchronous :: recvbuf(:, :)
    integer :: ierr
    if (ex%n > size(recvbuf, 2)) call internal_error('exchange_wait', &
      'the receive buffer has fewer columns than partners')
    if (ex%n > 0) call MPI_Waitall(2 * ex%n, ex%req, MPI_STATUSES_IGNORE, ierr)
    ex%n = 0
  end subroutine exchange_wait

  include 'm_comm_backend_error.inc'

end module m_comm_backend
