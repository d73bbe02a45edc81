!> Work-weighted re-partitioning with block migration (DESIGN section 3, manual/scale.md). Every
!> &run rebalance_every steps (0: never) the blocks' measured work (m_balance: the seconds of their
!> stage work since the last check) is gathered into one table by block id, the same on every rank;
!> its imbalance under the owners in use is logged. When it passes &run rebalance_threshold (0:
!> never), METIS partitions the block graph again with the measured seconds as weights
!> (m_partition, rank 0, broadcast); when that is predicted to remove enough of the excess
!> (balance_gain) and leaves no rank empty, every block whose owner changes moves with its whole
!> state: the conserved variables, level sets and transported variables of every phase with their
!> halo (q), the step-start copy (q0) and right-hand side (rhs), the dormant flag, and with a
!> cut-cell phase its content, fractions (now and at the last step's end), face geometry and
!> cut-cell flags (m_gfm_cut). The blocks go one per partner per round as point-to-point messages
!> through m_comm's exchange (MPI or coarray back end); the halo plan is built again for the new
!> owners, and the per-block arrays of the fix and the work accumulators are sized for the new
!> blocks (the fix's are reset at every step's start). Everything else a step carries over (clock,
!> fix and cut totals, counters) is not per block. Which rank holds a block changes nothing in the
!> results: the reductions that steer the solution are max/min or sums in block order, and the sums
!> of history.csv run over block ids (comm_sum_by_key). The timing makes the schedule of migrations
!> differ from run to run; the fields do not.
module m_rebalance
  use m_kinds, only: wp, line_len
  use m_simulation, only: sim_t, sim_plan
  use m_blocks, only: block_t, blocks_allocate
  use m_euler, only: cut_faces_t
  use m_gfm_cut, only: cut_boxes
  use m_partition, only: partition_owner
  use m_balance, only: balance_imbalance, balance_loads, balance_rank_work, balance_weights, &
    balance_relabel, balance_start, balance_note, balance_note_move, balance_gain
  use m_comm, only: comm_rank, comm_size, comm_sum_array, comm_bcast, comm_is_root, &
    comm_max, comm_wtime, comm_exchange_t, exchange_setup, exchange_start, exchange_wait
  use m_errors, only: log_line
  implicit none
  private
  public :: rebalance_check

  !> the ids of the blocks that move between this rank and one partner, in id order
  type :: moves_t
    integer, allocatable :: send(:), recv(:)
  end type moves_t

  !> A block of this rank taken out of sim while the blocks are redistributed, with its
  !> per-block parts.
  type :: held_cut_t   !< one cut phase's parts of a held block (m_gfm_cut's cut_t)
    real(wp), allocatable :: c(:, :, :, :), c0(:, :, :, :), alpha_n(:, :, :)
    type(cut_faces_t) :: faces
    real(wp), allocatable :: ext(:, :, :), ext_n(:, :, :)
  end type held_cut_t
  type :: held_t
    type(block_t) :: blk
    logical :: dormant = .false.
    type(held_cut_t), allocatable :: cut(:)   !< (cut phase)
  end type held_t

contains

  !> At a check step: measure, log, and re-partition and migrate when the imbalance passes
  !> the threshold. Every rank calls it after every step.
  subroutine rebalance_check(sim)
    type(sim_t), intent(inout) :: sim
    real(wp), allocatable :: cost(:), wall(:)
    real(wp), allocatable :: rank_work(:)
    integer, allocatable :: owner(:)
    real(wp) :: measured, predicted, t0, seconds
    integer :: b, np, moved, r
    logical :: accept
    character(len=line_len) :: line
    if (sim%bal%every <= 0) return
    np = comm_size()
    if (np == 1 .or. mod(sim%clk%step, sim%bal%every) /= 0) return
    allocate(cost(sim%lay%nblocks), wall(sim%lay%nblocks), owner(sim%lay%nblocks))
    cost = 0.0_wp
    wall = 0.0_wp
    do b = 1, size(sim%blocks)
      cost(sim%blocks(b)%id) = sim%bal%cost(b)
      wall(sim%blocks(b)%id) = sim%bal%wall(b)
    end do
    ! one non-zero term per entry: the same table on every rank
    allocate(rank_work(0:np - 1))
    rank_work = 0.0_wp
    rank_work(comm_rank()) = balance_rank_work(sim%bal)
    call comm_sum_array(cost)
    call comm_sum_array(wall)
    call comm_sum_array(rank_work)
    measured = balance_imbalance(sim%lay%owner, cost, np)
    call balance_note(sim%bal, sim%clk%step, measured, &
      balance_loads(sim%lay%owner, cost, np), balance_imbalance(sim%lay%owner, wall, np), &
      maxval(rank_work) / max(sum(rank_work) / np, tiny(1.0_wp)))
    write(line, '(a,i0,a,f7.3,a,i0,a,f10.3,a,f7.3,a,f7.3,a)') 'balance: step ', &
      sim%clk%step, ', imbalance ', measured, ' (max over mean of the ranks'' work over ', &
      sim%bal%every, ' steps; ', sum(cost), ' s in all; wall times ', &
      sim%bal%checks(5, sim%bal%nchecks), '; all work ', sim%bal%checks(6, sim%bal%nchecks), ')'
    call log_line(line)
    if (sim%bal%threshold > 0.0_wp .and. measured > sim%bal%threshold) then
      call partition_owner(sim%lay, balance_weights(cost, sim%lay%active), owner)
      call balance_relabel(sim%lay%owner, owner, np)
      predicted = balance_imbalance(owner, cost, np)
      moved = count(owner /= sim%lay%owner .and. sim%lay%active)
      accept = predicted <= 1.0_wp + (1.0_wp - balance_gain) * (measured - 1.0_wp) &
        .and. moved > 0 .and. all([(count(owner == r) > 0, r = 0, np - 1)])
      call comm_bcast(accept, 0)
      if (accept) then
        t0 = comm_wtime()
        call migrate(sim, owner)
        seconds = comm_max(comm_wtime() - t0)
        call balance_note_move(sim%bal, sim%clk%step, measured, predicted, moved, seconds)
        write(line, '(a,i0,a,i0,a,f7.3,a,f7.3,a,f8.3,a)') 'balance: step ', sim%clk%step, &
          ', migrated ', moved, ' blocks (imbalance ', measured, ', predicted ', predicted, &
          '; ', seconds, ' s)'
      else
        write(line, '(a,i0,a,f7.3,a)') 'balance: step ', sim%clk%step, &
          ', no migration (a new partition predicts ', predicted, ')'
      end if
      call log_line(line)
    end if
    call balance_start(sim%bal, size(sim%blocks))
  end subroutine rebalance_check

  !> Move every block whose owner changes to owner(id), with its whole state, and rebuild
  !> what depends on which blocks a rank holds.
  subroutine migrate(sim, owner)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: owner(:)
    type(held_t), allocatable :: old(:)
    type(moves_t), allocatable :: mv(:)
    integer, allocatable :: old_owner(:), local_old(:), local_new(:), partner(:), cap(:), &
      scount(:), rcount(:)
    real(wp), allocatable :: sendbuf(:, :), recvbuf(:, :)
    type(comm_exchange_t) :: ex
    integer :: me, np, id, b, m, p, k, nrounds, capacity
    me = comm_rank()
    np = comm_size()
    old_owner = sim%lay%owner
    call hold_blocks(sim, old)
    allocate(local_old(sim%lay%nblocks), local_new(sim%lay%nblocks))
    local_old = 0
    do b = 1, size(old)
      local_old(old(b)%blk%id) = b
    end do
    sim%lay%owner = owner
    call blocks_allocate(sim%lay, me, sim%ph%nvar, sim%blocks)
    call size_parts(sim)
    local_new = 0
    do b = 1, size(sim%blocks)
      local_new(sim%blocks(b)%id) = b
    end do
    ! the blocks that stay: their arrays change hands without a copy
    do b = 1, size(sim%blocks)
      id = sim%blocks(b)%id
      if (local_old(id) > 0) call restore_block(sim, b, old(local_old(id)))
    end do
    ! partners (in rank order) and the blocks to and from each, in id order
    allocate(partner(0))
    do p = 0, np - 1
      if (p == me) cycle
      if (any(old_owner == me .and. owner == p) .or. any(old_owner == p .and. owner == me)) &
        partner = [partner, p]
    end do
    allocate(mv(size(partner)))
    nrounds = 0
    do m = 1, size(partner)
      mv(m)%send = pack([(id, id = 1, size(owner))], old_owner == me .and. owner == partner(m))
      mv(m)%recv = pack([(id, id = 1, size(owner))], old_owner == partner(m) .and. owner == me)
      nrounds = max(nrounds, size(mv(m)%send), size(mv(m)%recv))
    end do
    nrounds = comm_max(nrounds)
    capacity = message_capacity(sim)
    allocate(cap(size(partner)), scount(size(partner)), rcount(size(partner)))
    cap = capacity
    allocate(sendbuf(capacity, max(1, size(partner))), recvbuf(capacity, max(1, size(partner))))
    ! collective (the coarray back end sizes its inbox); the halo plan's set-up follows
    call exchange_setup(ex, partner, cap)
    ! one block per partner and direction per round: the buffers hold one block each
    do k = 1, nrounds
      do m = 1, size(partner)
        scount(m) = 0
        rcount(m) = 0
        if (k <= size(mv(m)%send)) call pack_block(sim, old(local_old(mv(m)%send(k))), &
          sendbuf(:, m), scount(m))
        if (k <= size(mv(m)%recv)) rcount(m) = capacity
      end do
      if (size(partner) > 0) then
        call exchange_start(ex, partner, sendbuf, scount, recvbuf, rcount)
        call exchange_wait(ex, recvbuf)
      end if
      do m = 1, size(partner)
        if (k <= size(mv(m)%recv)) call unpack_block(sim, local_new(mv(m)%recv(k)), &
          recvbuf(:, m))
      end do
    end do
    call sim_plan(sim)
  end subroutine migrate

  !> This rank's blocks and their per-block parts, taken out of sim.
  subroutine hold_blocks(sim, old)
    type(sim_t), intent(inout) :: sim
    type(held_t), allocatable, intent(out) :: old(:)
    integer :: b, k
    allocate(old(size(sim%blocks)))
    do b = 1, size(sim%blocks)
      call move_alloc(sim%blocks(b)%q, old(b)%blk%q)
      call move_alloc(sim%blocks(b)%q0, old(b)%blk%q0)
      call move_alloc(sim%blocks(b)%rhs, old(b)%blk%rhs)
      old(b)%blk%id = sim%blocks(b)%id
      old(b)%dormant = sim%gf%dormant(b)
      if (.not. sim%cut(1)%on) cycle
      allocate(old(b)%cut(size(sim%cut)))
      do k = 1, size(sim%cut)
        associate (h => old(b)%cut(k), cut => sim%cut(k))
          h%c = cut%c(:, :, :, :, b)
          h%c0 = cut%c0(:, :, :, :, b)
          h%alpha_n = cut%alpha_n(:, :, :, b)
          call move_alloc(cut%faces(b)%ax, h%faces%ax)
          call move_alloc(cut%faces(b)%ay, h%faces%ay)
          call move_alloc(cut%faces(b)%az, h%faces%az)
          call move_alloc(cut%faces(b)%alpha, h%faces%alpha)
          call move_alloc(cut%faces(b)%plane, h%faces%plane)
          call move_alloc(cut%faces(b)%partial, h%faces%partial)
          call move_alloc(cut%ext(b)%a, h%ext)
          call move_alloc(cut%ext_n(b)%a, h%ext_n)
        end associate
      end do
    end do
    deallocate(sim%blocks)
  end subroutine hold_blocks

  !> The per-block parts of sim sized for its (new) blocks: the dormant flags, the cut-cell
  !> arrays, the fix's domain-side rates (zero: set again in every step) and the
  !> accumulators of the block work.
  subroutine size_parts(sim)
    type(sim_t), intent(inout) :: sim
    integer :: nb, n(3), k
    nb = size(sim%blocks)
    deallocate(sim%gf%dormant)
    if (allocated(sim%gf%rested)) deallocate(sim%gf%rested)
    allocate(sim%gf%dormant(nb))
    sim%gf%dormant = .false.
    do k = 1, size(sim%cut)
      if (.not. sim%cut(k)%on) cycle
      associate (cut => sim%cut(k))
        n = sim%lay%nmax
        deallocate(cut%c, cut%c0, cut%alpha_n, cut%faces, cut%ext, cut%ext_n)
        allocate(cut%c(n(1), n(2), n(3), sim%ph%nflow, nb), cut%faces(nb), cut%ext(nb), &
          cut%ext_n(nb))
        allocate(cut%c0, mold=cut%c)
        allocate(cut%alpha_n(n(1), n(2), n(3), nb))
        cut%c = 0.0_wp
        cut%c0 = 0.0_wp
        cut%alpha_n = 0.0_wp
        call cut_boxes(cut, nb)
      end associate
    end do
    if (allocated(sim%fix%bflux)) then
      n(1:2) = shape(sim%fix%bflux(:, :, 1, 1))
      deallocate(sim%fix%bflux)
      allocate(sim%fix%bflux(n(1), n(2), nb, 3))
      sim%fix%bflux = 0.0_wp
    end if
    call balance_start(sim%bal, nb)
  end subroutine size_parts

  !> Block b of sim (new index) takes the state of the held block h of this rank.
  subroutine restore_block(sim, b, h)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b
    type(held_t), intent(inout) :: h
    integer :: k
    call move_alloc(h%blk%q, sim%blocks(b)%q)
    call move_alloc(h%blk%q0, sim%blocks(b)%q0)
    call move_alloc(h%blk%rhs, sim%blocks(b)%rhs)
    sim%gf%dormant(b) = h%dormant
    if (.not. sim%cut(1)%on) return
    do k = 1, size(sim%cut)
      associate (hc => h%cut(k), cut => sim%cut(k))
        cut%c(:, :, :, :, b) = hc%c
        cut%c0(:, :, :, :, b) = hc%c0
        cut%alpha_n(:, :, :, b) = hc%alpha_n
        call move_alloc(hc%faces%ax, cut%faces(b)%ax)
        call move_alloc(hc%faces%ay, cut%faces(b)%ay)
        call move_alloc(hc%faces%az, cut%faces(b)%az)
        call move_alloc(hc%faces%alpha, cut%faces(b)%alpha)
        call move_alloc(hc%faces%plane, cut%faces(b)%plane)
        call move_alloc(hc%faces%partial, cut%faces(b)%partial)
        call move_alloc(hc%ext, cut%ext(b)%a)
        call move_alloc(hc%ext_n, cut%ext_n(b)%a)
      end associate
    end do
  end subroutine restore_block

  !> The longest message: one block of the largest extent with everything it carries (a
  !> 3D array of the cut geometry with its bounds is at most the padded block plus one).
  integer function message_capacity(sim) result(c)
    type(sim_t), intent(in) :: sim
    integer :: ni, npad
    ni = product(sim%lay%nmax)
    npad = product(sim%lay%nmax + 2 * sim%lay%ng)
    c = 1 + sim%ph%nvar * (npad + 2 * ni)
    if (sim%cut(1)%on) c = c + size(sim%cut) * ((2 * sim%ph%nflow + 1) * ni &
      + 8 * (7 + product(sim%lay%nmax + 2 * sim%lay%ng + 1)))
  end function message_capacity

  !> The held block h into buf(1:len): the dormant flag, q (with its halo), q0, rhs, and the
  !> cut-cell parts (content, start content, fractions, faces and halo fractions, each
  !> array of the geometry with its bounds).
  subroutine pack_block(sim, h, buf, len)
    type(sim_t), intent(in) :: sim
    type(held_t), intent(in) :: h
    real(wp), intent(out) :: buf(:)
    integer, intent(out) :: len
    integer :: k
    len = 0
    call put([merge(1.0_wp, 0.0_wp, h%dormant)])
    call put(reshape(h%blk%q, [size(h%blk%q)]))
    call put(reshape(h%blk%q0, [size(h%blk%q0)]))
    call put(reshape(h%blk%rhs, [size(h%blk%rhs)]))
    if (.not. sim%cut(1)%on) return
    do k = 1, size(sim%cut)
      associate (hc => h%cut(k))
        call put(reshape(hc%c, [size(hc%c)]))
        call put(reshape(hc%c0, [size(hc%c0)]))
        call put(reshape(hc%alpha_n, [size(hc%alpha_n)]))
        call put_array(hc%faces%ax)
        call put_array(hc%faces%ay)
        call put_array(hc%faces%az)
        call put_array(hc%faces%alpha)
        call put_array(hc%faces%plane)
        call put_array(hc%ext)
        call put_array(hc%ext_n)
        if (allocated(hc%faces%partial)) then
          call put([1.0_wp, real(lbound(hc%faces%partial), wp), &
            real(ubound(hc%faces%partial), wp)])
          call put(reshape(merge(1.0_wp, 0.0_wp, hc%faces%partial), [size(hc%faces%partial)]))
        else
          call put([0.0_wp])
        end if
      end associate
    end do

  contains

    subroutine put(x)
      real(wp), intent(in) :: x(:)
      buf(len + 1:len + size(x)) = x
      len = len + size(x)
    end subroutine put

    subroutine put_array(a)
      real(wp), allocatable, intent(in) :: a(:, :, :)
      if (.not. allocated(a)) then
        call put([0.0_wp])
        return
      end if
      call put([1.0_wp, real(lbound(a), wp), real(ubound(a), wp)])
      call put(reshape(a, [size(a)]))
    end subroutine put_array

  end subroutine pack_block

  !> Block b of sim (new index, allocated for its extent) from a message of pack_block.
  subroutine unpack_block(sim, b, buf)
    type(sim_t), intent(inout) :: sim
    integer, intent(in) :: b
    real(wp), intent(in) :: buf(:)
    integer :: pos, k
    real(wp), allocatable :: mask(:, :, :)   !< the cut faces' partial flags, as 0 / 1
    pos = 0
    associate (blk => sim%blocks(b))
      sim%gf%dormant(b) = buf(1) > 0.5_wp
      pos = 1
      blk%q = reshape(take(size(blk%q)), shape(blk%q))
      blk%q0 = reshape(take(size(blk%q0)), shape(blk%q0))
      blk%rhs = reshape(take(size(blk%rhs)), shape(blk%rhs))
    end associate
    if (.not. sim%cut(1)%on) return
    do k = 1, size(sim%cut)
      associate (cut => sim%cut(k))
        cut%c(:, :, :, :, b) = reshape(take(size(cut%c(:, :, :, :, b))), &
          shape(cut%c(:, :, :, :, b)))
        cut%c0(:, :, :, :, b) = reshape(take(size(cut%c0(:, :, :, :, b))), &
          shape(cut%c0(:, :, :, :, b)))
        cut%alpha_n(:, :, :, b) = reshape(take(size(cut%alpha_n(:, :, :, b))), &
          shape(cut%alpha_n(:, :, :, b)))
        call take_array(cut%faces(b)%ax)
        call take_array(cut%faces(b)%ay)
        call take_array(cut%faces(b)%az)
        call take_array(cut%faces(b)%alpha)
        call take_array(cut%faces(b)%plane)
        call take_array(cut%ext(b)%a)
        call take_array(cut%ext_n(b)%a)
        call take_array(mask)
        if (allocated(cut%faces(b)%partial)) deallocate(cut%faces(b)%partial)
        if (allocated(mask)) then
          allocate(cut%faces(b)%partial(lbound(mask, 1):ubound(mask, 1), &
            lbound(mask, 2):ubound(mask, 2), lbound(mask, 3):ubound(mask, 3)))
          cut%faces(b)%partial = mask > 0.5_wp
        end if
      end associate
    end do

  contains

    function take(n) result(x)
      integer, intent(in) :: n
      real(wp) :: x(n)
      x = buf(pos + 1:pos + n)
      pos = pos + n
    end function take

    subroutine take_array(a)
      real(wp), allocatable, intent(inout) :: a(:, :, :)
      integer :: lb(3), ub(3)
      real(wp) :: head(6)
      if (allocated(a)) deallocate(a)
      pos = pos + 1
      if (.not. buf(pos) > 0.5_wp) return
      head = take(6)
      lb = nint(head(1:3))
      ub = nint(head(4:6))
      allocate(a(lb(1):ub(1), lb(2):ub(2), lb(3):ub(3)))
      a = reshape(take(size(a)), shape(a))
    end subroutine take_array

  end subroutine unpack_block

end module m_rebalance
