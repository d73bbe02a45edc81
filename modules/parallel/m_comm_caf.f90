!> The coarray back end of m_comm (DESIGN section 3), compiled by `make COMM=caf` with
!> OpenCoarrays (`caf`, run by `cafrun`). Rank r is image r + 1.
!>  - Halo exchange: every image owns one coarray inbox holding, for each partner, two
!>    slots sized for that partner's largest message. A sender puts its packed buffer
!>    straight into its slot in the receiver's inbox, then both sides `sync images` with
!>    their partner set (each partner listed once) and the receiver copies the slot out.
!>    Successive exchanges alternate between the two slots, so a fast sender's next put
!>    cannot overwrite a message its partner is still copying out: before it can put
!>    into the same slot again, one more `sync images` with that partner lies between.
!>  - Reductions: min and max by co_min/co_max (exact in any order), integer sums by
!>    co_sum; real sums in a fixed order, the same for a given number of images however
!>    the messages arrive: a binary tree over the images in order (image 1 adds the
!>    partial sum of images 2, image 1 + 2 that of 3 + 4, ...) by coarray puts, then
!>    co_broadcast. Broadcasts by co_broadcast, barrier by `sync all`, abort by
!>    `error stop`.
!> The program stays an MPI program underneath (OpenCoarrays runs on Open MPI): parallel
!> HDF5's communicator, the wall clock and the node's ranks come from MPI in m_comm.
!> Only the latest exchange set-up owns the inbox (SABRE builds one halo plan per run);
!> an exchange started on an older set-up stops the run with an internal error.
module m_comm_backend
  use mpi_f08, only: MPI_Finalize, MPI_Finalized
  use m_kinds, only: wp, i8
  implicit none
  private
  include 'm_comm_backend.inc'

  character(len=*), parameter :: comm_backend_name = 'coarray'

  integer :: me = 1            !< this image
  integer :: nimages = 1
  integer :: generation = 0    !< exchange set-ups so far; the latest owns the inbox

  !> Halo messages arrive here (slots per partner, see the module text); the same size on
  !> every image: the largest any image needs.
  real(wp), allocatable :: inbox(:)[:]
  !> Set-up scratch: on image i, slot_start(p) and slot_size(p) describe the slot (parity
  !> 0; parity 1 follows it) that image p puts its messages into.
  integer, allocatable :: slot_start(:)[:], slot_size(:)[:]
  !> Fixed-order sums: column l takes the partial sum of the right subtree at tree level l.
  real(wp), allocatable :: partial(:, :)[:]

  !> One plan's messages: the partner images and both ends' slots.
  type :: comm_exchange_t
    integer :: n = 0                  !< partners of the exchange in progress (0: none)
    integer :: generation = -1        !< the set-up this exchange belongs to
    integer :: parity = 0             !< slot of the next exchange (0 or 1)
    integer, allocatable :: image(:)  !< partner images
    integer, allocatable :: mine(:), my_size(:)        !< partner's slot in my inbox
    integer, allocatable :: theirs(:), their_size(:)   !< my slot in the partner's inbox
    integer, allocatable :: rcount(:) !< lengths of the messages in progress
  end type comm_exchange_t

  interface
    subroutine caf_finalize() bind(C, name='_gfortran_caf_finalize')
    end subroutine caf_finalize
  end interface

contains

  subroutine backend_init(rank, nranks)
    integer, intent(out) :: rank, nranks
    me = this_image()
    nimages = num_images()
    rank = me - 1
    nranks = nimages
    if (.not. allocated(slot_start)) allocate(slot_start(nimages)[*], slot_size(nimages)[*])
  end subroutine backend_init

  !> End the coarray run as the end of the main program would (gfortran's coarray ABI):
  !> every image synchronises, the library frees its coarrays and finalises MPI.
  subroutine backend_finalize()
    integer :: ierr
    logical :: done
    call MPI_Finalized(done, ierr)
    if (done) return
    sync all
    call caf_finalize()
  end subroutine backend_finalize

  subroutine backend_barrier()
    sync all
  end subroutine backend_barrier

  subroutine backend_abort(code)
    integer, intent(in) :: code
    error stop code, quiet=.true.
  end subroutine backend_abort

  !> The largest x over the images (exact in any order); m_comm makes min and the integer
  !> versions of it (every 32-bit integer is a double exactly).
  real(wp) function backend_max(x) result(r)
    real(wp), intent(in) :: x
    r = x
    call co_max(r)
  end function backend_max

  !> x = the sum of x over the images, added in a fixed order: a binary tree over the
  !> images in index order; at level l (span s = 2**(l-1)) image i with mod(i-1, 2s) = s
  !> puts its partial sum to image i - s and leaves the tree, image i - s adds it on its
  !> right. Image 1 ends with the total and broadcasts it.
  subroutine backend_sum_real(x)
    real(wp), intent(inout) :: x(:)
    integer :: n, levels, s, lev, r
    if (nimages == 1) return
    n = size(x)
    levels = 0
    s = 1
    do while (s < nimages)
      levels = levels + 1
      s = 2 * s
    end do
    if (allocated(partial)) then
      if (size(partial, 1) < n) deallocate(partial)
    end if
    if (.not. allocated(partial)) allocate(partial(max(n, 16), levels)[*])
    r = me - 1
    s = 1
    do lev = 1, levels
      if (mod(r, 2 * s) == s) then
        partial(1:n, lev)[me - s] = x
        sync images (me - s)
        exit
      else if (mod(r, 2 * s) == 0 .and. r + s < nimages) then
        sync images (me + s)
        x = x + partial(1:n, lev)
      end if
      s = 2 * s
    end do
    call co_broadcast(x, source_image=1)
  end subroutine backend_sum_real

  integer(i8) function backend_sum_int8(x) result(r)
    integer(i8), intent(in) :: x
    r = x
    call co_sum(r)
  end function backend_sum_int8

  subroutine backend_bcast_chars(text, root)
    character(len=*), intent(inout) :: text
    integer, intent(in) :: root
    call co_broadcast(text, source_image=root + 1)
  end subroutine backend_bcast_chars

  subroutine backend_bcast_int(x, root)
    integer, intent(inout) :: x(:)
    integer, intent(in) :: root
    call co_broadcast(x, source_image=root + 1)
  end subroutine backend_bcast_int

  subroutine backend_bcast_real(x, root)
    real(wp), intent(inout) :: x
    integer, intent(in) :: root
    call co_broadcast(x, source_image=root + 1)
  end subroutine backend_bcast_real

  subroutine backend_bcast_logical(x, root)
    logical, intent(inout) :: x
    integer, intent(in) :: root
    call co_broadcast(x, source_image=root + 1)
  end subroutine backend_bcast_logical

  !> Collective: every image calls it once per plan, before that plan's first exchange.
  !> partner(m) is a rank this image exchanges with (each once, never itself) and
  !> capacity(m) the longest message it will receive from it. The partner relation is
  !> symmetric. Grows the inbox if any image needs more, and tells each image where its
  !> slot in each partner's inbox is.
  subroutine exchange_setup(ex, partner, capacity)
    type(comm_exchange_t), intent(inout) :: ex
    integer, intent(in) :: partner(:), capacity(:)
    integer :: m, n, need, pos
    n = size(partner)
    if (size(capacity) /= n) call internal_error('exchange_setup', 'one capacity per partner')
    generation = generation + 1
    ex%generation = generation
    ex%n = 0
    ex%parity = 0
    if (allocated(ex%mine)) deallocate(ex%mine, ex%theirs, ex%their_size, ex%rcount)
    ex%image = partner + 1
    ex%my_size = max(capacity, 1)
    allocate(ex%mine(n), ex%theirs(n), ex%their_size(n), ex%rcount(n))
    need = 2 * sum(ex%my_size)
    call co_max(need)
    if (allocated(inbox)) then
      if (size(inbox) < need) deallocate(inbox)
    end if
    if (.not. allocated(inbox)) allocate(inbox(max(need, 1))[*])
    slot_start = -1
    slot_size = 0
    pos = 0
    do m = 1, n
      ex%mine(m) = pos
      slot_start(ex%image(m)) = pos
      slot_size(ex%image(m)) = ex%my_size(m)
      pos = pos + 2 * ex%my_size(m)
    end do
    sync all
    do m = 1, n
      ex%theirs(m) = slot_start(me)[ex%image(m)]
      ex%their_size(m) = slot_size(me)[ex%image(m)]
    end do
    sync all
    if (n > 0) then
      if (any(ex%theirs < 0)) call internal_error('exchange_setup', &
        'a partner does not list this image (the halo plan is not symmetric)')
    end if
  end subroutine exchange_setup

  !> Start one exchange: put sendbuf(1:scount(m), m) into partner(m)'s inbox. recvbuf
  !> receives the messages in exchange_wait.
  subroutine exchange_start(ex, partner, sendbuf, scount, recvbuf, rcount)
    type(comm_exchange_t), intent(inout) :: ex
    integer, intent(in) :: partner(:), scount(:), rcount(:)
    real(wp), intent(in), asynchronous :: sendbuf(:, :)
    real(wp), intent(inout), asynchronous :: recvbuf(:, :)
    integer :: m, o
    if (ex%generation /= generation) call internal_error('exchange_start', &
      'this exchange was set up before the latest exchange_setup')
    if (size(partner) /= size(ex%image)) call internal_error('exchange_start', &
      'not the partners of exchange_setup')
    if (any(partner + 1 /= ex%image)) call internal_error('exchange_start', &
      'not the partners of exchange_setup')
    if (any(scount > ex%their_size) .or. any(rcount > ex%my_size)) &
      call internal_error('exchange_start', 'a message is longer than its capacity')
    if (size(recvbuf, 2) < size(partner) .or. size(recvbuf, 1) < maxval([0, rcount])) &
      call internal_error('exchange_start', 'the receive buffer is too small')
    ex%n = size(partner)
    ex%rcount = rcount
    do m = 1, ex%n
      o = ex%theirs(m) + ex%parity * ex%their_size(m)
      inbox(o + 1:o + scount(m))[ex%image(m)] = sendbuf(1:scount(m), m)
    end do
  end subroutine exchange_start

  !> Complete the exchange: synchronise with the partners, then copy each message out of
  !> the inbox into recvbuf(:, m).
  subroutine exchange_wait(ex, recvbuf)
    type(comm_exchange_t), intent(inout) :: ex
    real(wp), intent(inout), asynchronous :: recvbuf(:, :)
    integer :: m, o
    if (ex%n == 0) return
    sync images (ex%image)
    do m = 1, ex%n
      o = ex%mine(m) + ex%parity * ex%my_size(m)
      recvbuf(1:ex%rcount(m), m) = inbox(o + 1:o + ex%rcount(m))
    end do
    ex%parity = 1 - ex%parity
    ex%n = 0
  end subroutine exchange_wait

  include 'm_comm_backend_error.inc'

end module m_comm_backend
