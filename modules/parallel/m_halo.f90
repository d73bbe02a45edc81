!> Halo exchange between blocks (DESIGN section 3): every block's 4-deep halo over faces,
!> edges and corners is filled from the neighbouring block, by a local copy when the neighbour
!> is on this rank, otherwise through one packed message per partner rank (m_comm: MPI
!> nonblocking sends and receives, or coarray puts in the COMM=caf build). The plan is
!> built once from the layout (collectively: it also sets up m_comm's exchange): both sides
!> of a message list its pieces in the same order, by (receiving block id, direction), so
!> no piece carries a header. Regions with no neighbour block (domain
!> boundary, rigid obstacle) are left to m_boundary. Blocks may differ in extent (the last
!> block along a direction, m_layout): a box takes the extent of the block it lies in, and
!> across a face the two blocks agree in every other direction. The plan also counts what
!> the exchanges move (halo_counts_t: integer adds per message and per copy, no
!> communication), for run.json and manual/scale.md. An exchange may be split in two
!> (halo_exchange with split, halo_exchange_finish): between them the blocks that receive
!> nothing from other ranks (remote(b) false) have their whole halo and may be worked on
!> while the messages travel (m_step, &run overlap).
module m_halo
  use m_kinds, only: wp, i8
  use m_layout, only: layout_t, block_neighbor, block_extent
  use m_blocks, only: block_t
  use m_comm, only: comm_rank, comm_exchange_t, exchange_setup, exchange_start, exchange_wait
  implicit none
  private
  public :: halo_plan_t, halo_counts_t, halo_plan_build, halo_exchange, halo_refresh, &
    halo_refresh_boxes, halo_region, halo_exchange_finish

  !> One piece: a box of cells of a local block, and the box of its source block.
  type :: piece_t
    integer :: local = 0         !< index into this rank's blocks(:)
    integer :: src_local = 0     !< for local copies: index of the source block
    integer :: lo(3), hi(3)      !< box in the local block (halo box to fill, or box to send)
    integer :: slo(3), shi(3)    !< source box in the source block (local copies only)
    integer :: key1 = 0, key2 = 0 !< ordering key: receiving block id, direction index
  end type piece_t

  type :: partner_t
    integer :: rank = -1
    integer :: ncells_send = 0, ncells_recv = 0
    type(piece_t), allocatable :: send(:), recv(:)
  end type partner_t

  !> What this rank's calls of halo_exchange moved since the counts were last reset (the
  !> time loop resets them at its start and counts its steps): messages and bytes sent to
  !> other ranks, and bytes copied between its own blocks (halo_refresh's copies left out).
  !> A plan built again (halo_plan_build after a migration) keeps them.
  type :: halo_counts_t
    integer(i8) :: steps = 0, exchanges = 0, messages = 0, bytes = 0, copy_bytes = 0
  end type halo_counts_t

  type :: halo_plan_t
    integer :: ng(3) = 0         !< halo depth per direction (from the layout)
    integer :: ncopy = 0
    type(piece_t), allocatable :: copy(:)
    integer :: npartner = 0
    type(partner_t), allocatable :: partner(:)
    real(wp), allocatable :: sendbuf(:, :), recvbuf(:, :)
    type(comm_exchange_t) :: ex
    type(halo_counts_t) :: counts
    !> remote(b): block b's halo takes a piece from another rank (a message)
    logical, allocatable :: remote(:)
    !> the variables of the exchange started and not yet finished (none: last < first)
    integer :: pending_first = 1, pending_last = 0
  end type halo_plan_t

  integer(i8), parameter :: wp_bytes = storage_size(1.0_wp) / 8

contains

  !> Cell box of block id for direction dir: the halo to fill (role = 'h'), or the interior
  !> cells that a neighbour in direction dir needs from it (role = 's').
  !> depth: the cells exchanged across a face when less than the halo (a plan's depth).
  pure subroutine halo_region(lay, id, dir, role, lo, hi, depth)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id, dir(3)
    character, intent(in) :: role
    integer, intent(out) :: lo(3), hi(3)
    integer, intent(in), optional :: depth
    integer :: d, n, g, ext(3)
    ext = block_extent(lay, id)
    do d = 1, 3
      n = ext(d)
      g = lay%ng(d)
      if (present(depth)) g = min(g, depth)
      select case (dir(d))
      case (-1)
        if (role == 'h') then
          lo(d) = 1 - g; hi(d) = 0
        else
          lo(d) = 1; hi(d) = g
        end if
      case (1)
        if (role == 'h') then
          lo(d) = n + 1; hi(d) = n + g
        else
          lo(d) = n - g + 1; hi(d) = n
        end if
      case default
        lo(d) = 1; hi(d) = n
      end select
    end do
  end subroutine halo_region

  !> The plan of this rank's blocks; a plan built again (blocks migrated) keeps its counts.
  !> With faces_only, the halo beside each face of a block and not its edges and corners:
  !> enough where every stencil runs along one direction (the flow and strength kernels;
  !> not the level sets' and ghost fill's, m_simulation says when), at 79 % of the copies
  !> for blocks of 32^3. Every rank builds its plan the same way.
  subroutine halo_plan_build(lay, blocks, plan, faces_only, depth)
    type(layout_t), intent(in) :: lay
    type(block_t), intent(in) :: blocks(:)
    type(halo_plan_t), intent(inout) :: plan
    logical, intent(in), optional :: faces_only
    !> cells exchanged across each face, when less than the halo's depth (the rest of the
    !> halo is then never filled: for a scene whose stencils reach no further)
    integer, intent(in), optional :: depth
    integer :: me, b, nbr, dir(3), di, dj, dk, p, r, k, kdir, nb, maxs, maxr, nvq
    integer, allocatable :: local_of(:), pindex(:), ranks(:), capacity(:)
    type(piece_t) :: pc
    type(halo_counts_t) :: counts
    counts = plan%counts
    call plan_clear(plan)
    plan%counts = counts
    me = comm_rank()
    nb = size(blocks)
    plan%ng = lay%ng
    allocate(local_of(lay%nblocks), pindex(0:maxval(lay%owner)))
    local_of = 0
    do b = 1, nb
      local_of(blocks(b)%id) = b
    end do
    ! partners in increasing rank order
    pindex = 0
    plan%npartner = 0
    allocate(plan%copy(26 * max(nb, 1)), plan%remote(nb))
    plan%remote = .false.
    do b = 1, nb
      call each_direction(b)
    end do
    allocate(plan%partner(plan%npartner))
    r = 0
    do p = 0, ubound(pindex, 1)
      if (pindex(p) > 0) then
        r = r + 1
        pindex(p) = r
        plan%partner(r)%rank = p
        allocate(plan%partner(r)%send(0), plan%partner(r)%recv(0))
      end if
    end do
    ! second sweep: fill the pieces
    plan%ncopy = 0
    do b = 1, nb
      do dk = -dmax(3), dmax(3)
        do dj = -dmax(2), dmax(2)
          do di = -dmax(1), dmax(1)
            dir = [di, dj, dk]
            if (.not. wanted(dir)) cycle
            nbr = block_neighbor(lay, blocks(b)%id, dir)
            if (nbr <= 0) cycle
            kdir = 1 + (di + 1) + 3 * (dj + 1) + 9 * (dk + 1)
            pc%local = b
            call halo_region(lay, blocks(b)%id, dir, 'h', pc%lo, pc%hi, depth)
            call halo_region(lay, nbr, -dir, 's', pc%slo, pc%shi, depth)
            if (lay%owner(nbr) == me) then
              pc%src_local = local_of(nbr)
              plan%ncopy = plan%ncopy + 1
              plan%copy(plan%ncopy) = pc
            else
              plan%remote(b) = .true.
              r = pindex(lay%owner(nbr))
              pc%key1 = blocks(b)%id
              pc%key2 = kdir
              plan%partner(r)%recv = [plan%partner(r)%recv, pc]
              ! what the neighbour needs from this block: its halo in direction -dir
              call halo_region(lay, blocks(b)%id, dir, 's', pc%lo, pc%hi, depth)
              pc%key1 = nbr
              pc%key2 = 1 + (1 - di) + 3 * (1 - dj) + 9 * (1 - dk)
              plan%partner(r)%send = [plan%partner(r)%send, pc]
            end if
          end do
        end do
      end do
    end do
    maxs = 1
    maxr = 1
    do r = 1, plan%npartner
      call sort_pieces(plan%partner(r)%send)
      call sort_pieces(plan%partner(r)%recv)
      plan%partner(r)%ncells_send = 0
      do k = 1, size(plan%partner(r)%send)
        plan%partner(r)%ncells_send = plan%partner(r)%ncells_send &
          + product(plan%partner(r)%send(k)%hi - plan%partner(r)%send(k)%lo + 1)
      end do
      plan%partner(r)%ncells_recv = 0
      do k = 1, size(plan%partner(r)%recv)
        plan%partner(r)%ncells_recv = plan%partner(r)%ncells_recv &
          + product(plan%partner(r)%recv(k)%hi - plan%partner(r)%recv(k)%lo + 1)
      end do
      maxs = max(maxs, plan%partner(r)%ncells_send)
      maxr = max(maxr, plan%partner(r)%ncells_recv)
    end do
    ! buffers are sized per variable count at exchange time; remember cell counts here
    allocate(plan%sendbuf(maxs, max(plan%npartner, 1)), plan%recvbuf(maxr, max(plan%npartner, 1)))
    ! every rank (collective): a message carries at most every variable of q
    nvq = 0
    if (nb > 0) nvq = size(blocks(1)%q, 4)
    allocate(ranks(plan%npartner), capacity(plan%npartner))
    do r = 1, plan%npartner
      ranks(r) = plan%partner(r)%rank
      capacity(r) = plan%partner(r)%ncells_recv * nvq
    end do
    call exchange_setup(plan%ex, ranks, capacity)

  contains

    pure integer function dmax(d)
      integer, intent(in) :: d
      dmax = merge(1, 0, d <= lay%ndim)
    end function dmax

    !> whether the plan has the halo in direction dd: not the block itself; with faces_only,
    !> a face's alone
    pure logical function wanted(dd)
      integer, intent(in) :: dd(3)
      wanted = any(dd /= 0)
      if (present(faces_only)) wanted = wanted .and. .not. (faces_only .and. count(dd /= 0) > 1)
    end function wanted

    subroutine each_direction(bb)
      integer, intent(in) :: bb
      integer :: i, j, kk, nn
      do kk = -dmax(3), dmax(3)
        do j = -dmax(2), dmax(2)
          do i = -dmax(1), dmax(1)
            if (.not. wanted([i, j, kk])) cycle
            nn = block_neighbor(lay, blocks(bb)%id, [i, j, kk])
            if (nn <= 0) cycle
            if (lay%owner(nn) == me) cycle
            if (pindex(lay%owner(nn)) == 0) then
              pindex(lay%owner(nn)) = 1
              plan%npartner = plan%npartner + 1
            end if
          end do
        end do
      end do
    end subroutine each_direction

  end subroutine halo_plan_build

  !> plan back to an empty plan (its defaults; allocatable parts freed)
  subroutine plan_clear(plan)
    type(halo_plan_t), intent(out) :: plan
    plan%ncopy = 0
  end subroutine plan_clear

  !> Insertion sort by (key1, key2): the lists are short (tens of pieces).
  subroutine sort_pieces(list)
    type(piece_t), intent(inout) :: list(:)
    type(piece_t) :: t
    integer :: i, j
    do i = 2, size(list)
      t = list(i)
      j = i - 1
      do while (j >= 1)
        if (list(j)%key1 < t%key1 .or. &
          (list(j)%key1 == t%key1 .and. list(j)%key2 <= t%key2)) exit
        list(j + 1) = list(j)
        j = j - 1
      end do
      list(j + 1) = t
    end do
  end subroutine sort_pieces

  !> Fill the halos of variables first..nvar (first defaults to 1) of every block's q: the
  !> messages packed and sent, receives posted, the local copies while they travel, then
  !> the wait and the unpacking. A block b with skip(b) set takes only variables keep..nvar
  !> (none without keep) by local copy: the level sets of a dormant block, whose flow halo
  !> nothing reads (halo_refresh brings it up to date should the block wake). Messages
  !> between ranks carry every piece whole. With split set, it returns after the local
  !> copies: every block with remote(b) false has its halo, the others wait for
  !> halo_exchange_finish, which must come before the next exchange; the interior of any
  !> block may change in between (the messages are packed).
  subroutine halo_exchange(plan, blocks, nvar, first, skip, keep, split)
    type(halo_plan_t), intent(inout) :: plan
    type(block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: nvar
    integer, intent(in), optional :: first
    logical, intent(in), optional :: skip(:)
    integer, intent(in), optional :: keep
    logical, intent(in), optional :: split
    integer :: r, c, m1, nv, mc
    integer, allocatable :: scount(:), rcount(:), ranks(:)
    m1 = 1
    if (present(first)) m1 = first
    nv = nvar - m1 + 1
    if (size(plan%sendbuf, 1) < maxval([1, plan%partner%ncells_send]) * nv) then
      deallocate(plan%sendbuf, plan%recvbuf)
      allocate(plan%sendbuf(maxval([1, plan%partner%ncells_send]) * nv, &
        max(plan%npartner, 1)))
      allocate(plan%recvbuf(maxval([1, plan%partner%ncells_recv]) * nv, &
        max(plan%npartner, 1)))
    end if
    allocate(scount(plan%npartner), rcount(plan%npartner), ranks(plan%npartner))
    do r = 1, plan%npartner
      ranks(r) = plan%partner(r)%rank
      scount(r) = plan%partner(r)%ncells_send * nv
      rcount(r) = plan%partner(r)%ncells_recv * nv
      call carry(blocks, plan%partner(r)%send, m1, nvar, plan%sendbuf(:, r), into=.true.)
    end do
    if (plan%npartner > 0) call exchange_start(plan%ex, ranks, plan%sendbuf, scount, &
      plan%recvbuf, rcount)
    plan%pending_first = m1
    plan%pending_last = nvar
    plan%counts%exchanges = plan%counts%exchanges + 1
    plan%counts%messages = plan%counts%messages + count(scount > 0)
    plan%counts%bytes = plan%counts%bytes + wp_bytes * sum(int(scount, i8))
    do c = 1, plan%ncopy
      mc = m1
      if (present(skip)) then
        if (skip(plan%copy(c)%local)) then
          mc = nvar + 1
          if (present(keep)) mc = max(m1, keep)
        end if
      end if
      if (mc > nvar) cycle
      call copy_piece(blocks, plan%copy(c), mc, nvar)
      plan%counts%copy_bytes = plan%counts%copy_bytes + wp_bytes * (nvar - mc + 1) * &
        product(int(plan%copy(c)%hi - plan%copy(c)%lo + 1, i8))
    end do
    if (present(split)) then
      if (split) return
    end if
    call halo_exchange_finish(plan, blocks)
  end subroutine halo_exchange

  !> The rest of an exchange that halo_exchange began with split: wait for the messages and
  !> unpack them into the halos of the blocks with remote(b) set.
  subroutine halo_exchange_finish(plan, blocks)
    type(halo_plan_t), intent(inout) :: plan
    type(block_t), intent(inout) :: blocks(:)
    integer :: r
    if (plan%npartner > 0) call exchange_wait(plan%ex, plan%recvbuf)
    do r = 1, plan%npartner
      call carry(blocks, plan%partner(r)%recv, plan%pending_first, plan%pending_last, &
        plan%recvbuf(:, r), into=.false.)
    end do
    plan%pending_first = 1
    plan%pending_last = 0
  end subroutine halo_exchange_finish

  !> the pieces of one partner, variables m1..nvar, into its buffer (into) or out of it
  subroutine carry(blocks, list, m1, nvar, buf, into)
    type(block_t), intent(inout) :: blocks(:)
    type(piece_t), intent(in) :: list(:)
    integer, intent(in) :: m1, nvar
    real(wp), intent(inout) :: buf(:)
    logical, intent(in) :: into
    integer :: kp, pos, ni, mv, j, kk
    pos = 0
    do kp = 1, size(list)
      associate (lo => list(kp)%lo, hi => list(kp)%hi, q => blocks(list(kp)%local)%q)
        ni = hi(1) - lo(1) + 1
        do mv = m1, nvar
          do kk = lo(3), hi(3)
            do j = lo(2), hi(2)
              if (into) then
                buf(pos + 1:pos + ni) = q(lo(1):hi(1), j, kk, mv)
              else
                q(lo(1):hi(1), j, kk, mv) = buf(pos + 1:pos + ni)
              end if
              pos = pos + ni
            end do
          end do
        end do
      end associate
    end do
  end subroutine carry

  !> The local copies into block b alone, variables first..nvar: the halo that a call of
  !> halo_exchange with skip(b) left out, from the same (unchanged) neighbours. Pieces from
  !> other ranks were unpacked whole by that call.
  subroutine halo_refresh(plan, blocks, b, nvar, first)
    type(halo_plan_t), intent(in) :: plan
    type(block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: b, nvar, first
    integer :: c
    do c = 1, plan%ncopy
      if (plan%copy(c)%local == b) call copy_piece(blocks, plan%copy(c), first, nvar)
    end do
  end subroutine halo_refresh

  !> The local copies again where their source changed: box(:, :, b) holds the interior
  !> cells of block b that changed since the last exchange (low, high corner; empty when a
  !> low corner lies above its high one), and each local piece takes, variables first..nvar,
  !> the part of its source box that lies in its source block's box; touched(:, :, b): the
  !> smallest box (over block b's padded cells) of what block b took (empty: none). The rest
  !> of every halo holds what it held, which the whole exchange would give it again; only
  !> pieces between blocks of this rank (the caller exchanges everything when
  !> any block takes a message). A block b with skip(b) set takes none.
  subroutine halo_refresh_boxes(plan, blocks, box, nvar, first, skip, touched)
    type(halo_plan_t), intent(in) :: plan
    type(block_t), intent(inout) :: blocks(:)
    integer, intent(in) :: box(:, :, :)
    integer, intent(in) :: nvar, first
    logical, intent(in) :: skip(:)
    integer, intent(out) :: touched(:, :, :)
    integer :: c, a(3), z(3), s
    touched(1, :, :) = huge(1)
    touched(2, :, :) = -huge(1)
    do c = 1, plan%ncopy
      associate (pc => plan%copy(c))
        if (skip(pc%local)) cycle
        s = pc%src_local
        a = max(pc%slo, box(1, :, s))
        z = min(pc%slo + pc%hi - pc%lo, box(2, :, s))
        if (any(a > z)) cycle
        associate (dst => blocks(pc%local)%q, src => blocks(s)%q, o => pc%lo - pc%slo, &
            t => touched(:, :, pc%local))
          t(1, :) = min(t(1, :), a + o)
          t(2, :) = max(t(2, :), z + o)
          dst(a(1)+o(1):z(1)+o(1), a(2)+o(2):z(2)+o(2), a(3)+o(3):z(3)+o(3), first:nvar) = &
            src(a(1):z(1), a(2):z(2), a(3):z(3), first:nvar)
        end associate
      end associate
    end do
  end subroutine halo_refresh_boxes

  !> Piece pc of the local copies, variables m1..nvar: the box lo..hi of block pc%local
  !> from the box starting at slo of block pc%src_local (the same block along a periodic
  !> direction with a single block: the two boxes never overlap).
  subroutine copy_piece(blocks, pc, m1, nvar)
    type(block_t), intent(inout) :: blocks(:)
    type(piece_t), intent(in) :: pc
    integer, intent(in) :: m1, nvar
    integer :: shi(3)
    shi = pc%slo + pc%hi - pc%lo
    associate (lo => pc%lo, hi => pc%hi, slo => pc%slo, dst => blocks(pc%local)%q, &
        src => blocks(pc%src_local)%q)
      dst(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), m1:nvar) = &
        src(slo(1):shi(1), slo(2):shi(2), slo(3):shi(3), m1:nvar)
    end associate
  end subroutine copy_piece

end module m_halo
