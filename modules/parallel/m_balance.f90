!> The measure of load balance (DESIGN section 3, manual/scale.md). The work of a block is
!> the processor time it spends in the stage work of the steps since the last check (its
!> fluxes, sources, ghost-fluid faces, level-set rates, stage update and cell fallback: m_step
!> times it with balance_now and balance_add); the work of a rank is the sum over its blocks,
!> and the imbalance is the largest rank's work over the mean. Processor time, not wall time:
!> a rank that the system takes off its core for another program (a shared node) is not
!> charged for the time it did not run, so the measure is the code's own balance; the wall
!> time of the same work is kept beside it for the record. This module turns measured block
!> seconds into METIS weights,
!> computes the imbalance of any owner map for them (the one in use: measured; a proposed
!> one: predicted), and keeps the record of every check and migration for run.log and
!> run.json. m_rebalance decides and moves the blocks. Knows nothing of physics.
module m_balance
  use m_kinds, only: wp
  use m_comm, only: comm_wtime, comm_wait_seconds, comm_rank, comm_size
  implicit none
  private
  public :: balance_t, balance_start, balance_imbalance, balance_loads, balance_weights, &
    balance_relabel, balance_note, balance_note_move, balance_now, balance_add, &
    balance_rank_work

  !> A migration must remove at least this part of the measured excess imbalance (its
  !> prediction, on the measured block costs): a re-partition that the blocks' sizes cannot
  !> make much better is not worth moving the blocks for, and would repeat at every check.
  real(wp), parameter, public :: balance_gain = 0.25_wp

  !> The scale of METIS weights: the total work is about this many units.
  real(wp), parameter :: weight_scale = 1.0e6_wp

  type :: balance_t
    real(wp) :: threshold = 0.0_wp      !< migrate when the imbalance passes it (0: off)
    integer :: every = 0                !< steps between checks
    real(wp), allocatable :: cost(:)    !< (local block) processor seconds since the last check
    real(wp), allocatable :: wall(:)    !< (local block) wall seconds of the same work
    !> this rank's processor time and time waiting in blocking calls at the last check
    real(wp) :: mark(2) = 0.0_wp
    !> the record: per check (step, measured imbalance, the largest and the mean rank's
    !> work in seconds, the imbalance of the wall times, the imbalance of all the ranks'
    !> own work: balance_rank_work), and per migration (step, blocks
    !> moved, imbalance measured before, predicted after, seconds); steps and counts are
    !> held exactly as reals
    integer :: nchecks = 0, nmoves = 0
    real(wp), allocatable :: checks(:, :), moves(:, :)
    !> a test's handle (regress/unit/test_rebalance): one rank's block work is counted this
    !> many times over (environment SABRE_BALANCE_SKEW; 1 otherwise), so that a scene whose
    !> real imbalance is noise still migrates, and migration itself can be tested. The rank
    !> it falls on turns with the checks (rank mod(checks so far, ranks)): a partition that
    !> has absorbed one rank's skew meets it on the next rank at the next check, so every
    !> check sees a heavy rank, not only the first
    real(wp) :: skew = 1.0_wp
    real(wp) :: skew_now = 1.0_wp       !< the skew on this rank since the last check
  end type balance_t

contains

  !> The accumulators for nlocal blocks, zero (at the start, and after every check); the
  !> record's arrays at the start.
  subroutine balance_start(bal, nlocal)
    type(balance_t), intent(inout) :: bal
    integer, intent(in) :: nlocal
    character(len=32) :: env
    if (.not. allocated(bal%checks)) then
      allocate(bal%checks(6, 16), bal%moves(5, 16))
      call get_environment_variable('SABRE_BALANCE_SKEW', env)
      if (len_trim(env) > 0) read(env, *) bal%skew
    end if
    bal%skew_now = 1.0_wp
    if (comm_rank() == mod(bal%nchecks, comm_size())) bal%skew_now = bal%skew
    if (allocated(bal%cost)) deallocate(bal%cost, bal%wall)
    allocate(bal%cost(nlocal), bal%wall(nlocal))
    bal%cost = 0.0_wp
    bal%wall = 0.0_wp
    call cpu_time(bal%mark(1))
    bal%mark(2) = comm_wait_seconds()
  end subroutine balance_start

  !> This rank's own work since the last check, in processor seconds: all of it (the
  !> blocks' stage work, and what is not per block: ghost fill, reinitialisation, halo
  !> packing, side conditions, the time step, output) less the time spent waiting in
  !> blocking calls (m_comm's waiting clock), where a rank waits for the others.
  real(wp) function balance_rank_work(bal) result(w)
    type(balance_t), intent(in) :: bal
    call cpu_time(w)
    w = (w - bal%mark(1)) - (comm_wait_seconds() - bal%mark(2))
  end function balance_rank_work

  !> The clocks a block's work is measured with: [processor time of this process, wall time].
  function balance_now() result(t)
    real(wp) :: t(2)
    call cpu_time(t(1))
    t(2) = comm_wtime()
  end function balance_now

  !> Add the work since t0 (from balance_now) to local block b's account.
  subroutine balance_add(bal, b, t0)
    type(balance_t), intent(inout) :: bal
    integer, intent(in) :: b
    real(wp), intent(in) :: t0(2)
    real(wp) :: t(2)
    t = balance_now()
    bal%cost(b) = bal%cost(b) + bal%skew_now * (t(1) - t0(1))
    bal%wall(b) = bal%wall(b) + (t(2) - t0(2))
  end subroutine balance_add

  !> Largest over mean of the ranks' work for owner(id) in 0..nparts-1 (inactive blocks -1)
  !> and block work cost(id); 1 when there is no work. The sums run in block order, so every
  !> rank finds the same value from the same table.
  real(wp) function balance_imbalance(owner, cost, nparts) result(r)
    integer, intent(in) :: owner(:), nparts
    real(wp), intent(in) :: cost(:)
    real(wp) :: load(0:nparts - 1)
    load = balance_loads(owner, cost, nparts)
    r = 1.0_wp
    if (sum(load) > 0.0_wp) r = maxval(load) / (sum(load) / nparts)
  end function balance_imbalance

  !> The work of each rank 0..nparts-1: the sum of its blocks' cost(id), in block order.
  function balance_loads(owner, cost, nparts) result(load)
    integer, intent(in) :: owner(:), nparts
    real(wp), intent(in) :: cost(:)
    real(wp) :: load(0:nparts - 1)
    integer :: id
    load = 0.0_wp
    do id = 1, size(owner)
      if (owner(id) >= 0) load(owner(id)) = load(owner(id)) + cost(id)
    end do
  end function balance_loads

  !> METIS vertex weights (>= 1) from the measured block seconds: the total is scaled to
  !> about weight_scale units, so a dormant block (next to no work) weighs 1.
  function balance_weights(cost, active) result(w)
    real(wp), intent(in) :: cost(:)
    logical, intent(in) :: active(:)
    integer :: w(size(cost))
    real(wp) :: total
    total = sum(cost, mask=active)
    w = 1
    if (.not. total > 0.0_wp) return
    where (active) w = max(1, nint(weight_scale * cost / total))
  end function balance_weights

  !> The parts of a new partition renamed so that as many blocks as can stay where they
  !> are (METIS numbers its parts freely: a partition close to the old one may come back
  !> with the ranks' names swapped). Greedy: the parts in decreasing size, each to the free
  !> rank that holds most of its blocks now; a part that shares blocks with no free rank
  !> takes the lowest free rank. owner(id) in 0..nparts-1 or -1 (inactive), in place.
  subroutine balance_relabel(old, owner, nparts)
    integer, intent(in) :: old(:), nparts
    integer, intent(inout) :: owner(:)
    integer :: first(0:nparts), name(0:nparts - 1), shared(0:nparts - 1), fill(0:nparts - 1)
    integer :: by_part(size(owner))
    logical :: taken(0:nparts - 1), done(0:nparts - 1)
    integer :: k, p, r, id, m
    ! the blocks of each new part together: by_part(first(p) + 1:first(p + 1))
    first = 0
    do id = 1, size(owner)
      if (owner(id) >= 0) first(owner(id) + 1) = first(owner(id) + 1) + 1
    end do
    do p = 1, nparts
      first(p) = first(p) + first(p - 1)
    end do
    fill = first(0:nparts - 1)
    do id = 1, size(owner)
      if (owner(id) < 0) cycle
      fill(owner(id)) = fill(owner(id)) + 1
      by_part(fill(owner(id))) = id
    end do
    taken = .false.
    done = .false.
    name = -1
    shared = 0
    do k = 0, nparts - 1
      p = maxloc(first(1:nparts) - first(0:nparts - 1), dim=1, mask=.not. done) - 1
      done(p) = .true.
      do m = first(p) + 1, first(p + 1)
        r = old(by_part(m))
        if (r >= 0) shared(r) = shared(r) + 1
      end do
      r = maxloc(shared, dim=1, mask=.not. taken) - 1
      if (shared(r) > 0) then
        name(p) = r
        taken(r) = .true.
      end if
      do m = first(p) + 1, first(p + 1)
        if (old(by_part(m)) >= 0) shared(old(by_part(m))) = 0
      end do
    end do
    do p = 0, nparts - 1
      if (name(p) >= 0) cycle
      r = findloc(taken, .false., dim=1) - 1
      name(p) = r
      taken(r) = .true.
    end do
    do id = 1, size(owner)
      if (owner(id) >= 0) owner(id) = name(owner(id))
    end do
  end subroutine balance_relabel

  !> Record a check: its step, the measured imbalance, the largest and the mean of the
  !> ranks' work (s), the imbalance of the wall times and of the ranks' own work.
  subroutine balance_note(bal, step, imbalance, load, imbalance_wall, imbalance_all)
    type(balance_t), intent(inout) :: bal
    integer, intent(in) :: step
    real(wp), intent(in) :: imbalance, load(:), imbalance_wall, imbalance_all
    bal%nchecks = bal%nchecks + 1
    call grow(bal%checks, bal%nchecks, [real(step, wp), imbalance, maxval(load), &
      sum(load) / size(load), imbalance_wall, imbalance_all])
  end subroutine balance_note

  !> Record a migration: its step, the blocks moved, the imbalance measured before and
  !> predicted after, and the seconds it took.
  subroutine balance_note_move(bal, step, before, after, blocks, seconds)
    type(balance_t), intent(inout) :: bal
    integer, intent(in) :: step, blocks
    real(wp), intent(in) :: before, after, seconds
    bal%nmoves = bal%nmoves + 1
    call grow(bal%moves, bal%nmoves, [real(step, wp), real(blocks, wp), before, after, &
      seconds])
  end subroutine balance_note_move

  !> a(:, n) = x, a grown (doubled) when it is full
  subroutine grow(a, n, x)
    real(wp), allocatable, intent(inout) :: a(:, :)
    integer, intent(in) :: n
    real(wp), intent(in) :: x(:)
    real(wp), allocatable :: t(:, :)
    if (n > size(a, 2)) then
      allocate(t(size(a, 1), 2 * size(a, 2)))
      t(:, 1:size(a, 2)) = a
      call move_alloc(t, a)
    end if
    a(:, n) = x
  end subroutine grow

end module m_balance
