!> Unit test of the halo exchange (m_halo) on any number of ranks: in 2D and 3D layouts with
!> several blocks per rank, periodic and non-periodic directions, an inactive block, and cells
!> that are not a multiple of block (last blocks of another extent), every interior cell holds
!> a code of its global index; after one exchange every halo cell whose
!> source cell exists (through a neighbour block, with periodic wrap) must hold the code of
!> that source cell, for every variable. A second exchange of new values skips every other
!> block for variables 1-2 (halo_exchange's skip and keep): those keep the old values where
!> the source block is on this rank, take the new ones from other ranks and in variable 3;
!> halo_refresh then brings the skipped blocks up to date. The plan's counts of messages,
!> bytes sent and bytes copied on the rank agree with a hand count (count_case).
program test_halo
  use m_kinds, only: wp
  use m_layout, only: layout_t, layout_init, block_neighbor
  use m_blocks, only: block_t, blocks_allocate
  use m_halo, only: halo_plan_t, halo_plan_build, halo_exchange, halo_refresh
  use m_partition, only: partition_blocks
  use m_comm, only: comm_init, comm_rank, comm_size, comm_sum
  use m_kinds, only: i8
  use m_test_check, only: check_start, check, check_done
  implicit none
  call comm_init()
  call check_start('test_halo')
  call run_case(2, [32, 24, 1], [8, 8, 1], [.true., .false., .false.], 0)
  call run_case(2, [32, 32, 1], [8, 8, 1], [.false., .true., .false.], 6)
  call run_case(3, [16, 16, 12], [4, 8, 4], [.true., .true., .true.], 0)
  call run_case(3, [16, 12, 16], [8, 4, 4], [.false., .true., .false.], 5)
  ! cells not a multiple of block: a short last block (6, 4 cells) and a remainder thinner
  ! than the halo joined to the last block (10, 5 cells), with periodic wrap across them
  call run_case(2, [30, 26, 1], [8, 8, 1], [.true., .false., .false.], 0)
  call run_case(3, [18, 13, 12], [8, 4, 4], [.true., .true., .false.], 3)
  call count_case()
  call check_done()

contains

  pure real(wp) function code(g, m)
    integer, intent(in) :: g(3), m
    code = real(m, wp) + 10.0_wp * (g(1) + 1000 * (g(2) + 1000 * g(3)))
  end function code

  subroutine run_case(ndim, cells, bsize, periodic, hole)
    integer, intent(in) :: ndim, cells(3), bsize(3), hole
    logical, intent(in) :: periodic(3)
    type(layout_t) :: lay
    type(block_t), allocatable :: blocks(:)
    type(halo_plan_t) :: plan
    integer, allocatable :: work(:)
    logical, allocatable :: skip(:)
    integer :: b
    real(wp), parameter :: lo(3) = 0.0_wp, hi(3) = 1.0_wp
    call layout_init(lay, ndim, cells, bsize, lo, hi, periodic, .false.)
    if (hole > 0) lay%active(hole) = .false.
    allocate(work(lay%nblocks))
    work = 1
    call partition_blocks(lay, work)
    call blocks_allocate(lay, comm_rank(), 3, blocks)
    call halo_plan_build(lay, blocks, plan)
    do b = 1, size(blocks)
      blocks(b)%q = -1.0_wp
    end do
    call fill_interior(blocks, 0.0_wp)
    call halo_exchange(plan, blocks, 3)
    allocate(skip(size(blocks)))
    skip = .false.
    call check_halos(lay, blocks, skip, 0.0_wp)
    skip = [(mod(b, 2) == 1, b = 1, size(blocks))]
    call fill_interior(blocks, 0.5_wp)
    call halo_exchange(plan, blocks, 3, skip=skip, keep=3)
    call check_halos(lay, blocks, skip, 0.5_wp)
    do b = 1, size(blocks)
      if (skip(b)) call halo_refresh(plan, blocks, b, 2, 1)
    end do
    skip = .false.
    call check_halos(lay, blocks, skip, 0.5_wp)
  end subroutine run_case

  !> The plan's counts (halo_counts_t) against a hand count. 4 x 2 x 2 blocks of 8^3 cells,
  !> no periodic side, cut into slabs along x: block column ib (0-3) on rank ib P / 4 of P
  !> ranks. Across a cut between two ranks each of the 4 blocks of a column sends the block
  !> beside it a face (8 x 8 x 4 cells), two edges (8 x 4 x 4) and a corner (4^3): 576
  !> cells a variable, so a rank sends one message of 2304 cells a variable for each cut it
  !> touches. The rest of the halo with a neighbour block is copied on the rank: of a block
  !> in a column with columns on both sides (4 + 8 + 4) (8 + 4)^2 - 8^3 = 1792 cells, at an
  !> end of x (8 + 4)^3 - 8^3 = 1216, less 576 for each side whose column is on another rank.
  subroutine count_case()
    integer, parameter :: wp_bytes = storage_size(1.0_wp) / 8
    type(layout_t) :: lay
    type(block_t), allocatable :: blocks(:)
    type(halo_plan_t) :: plan
    integer :: id, ib, np, me, cuts, copy_cells, foreign
    integer :: column_rank(0:3)
    character(len=80) :: text
    real(wp), parameter :: lo(3) = 0.0_wp, hi(3) = 1.0_wp
    np = comm_size()
    me = comm_rank()
    call layout_init(lay, 3, [32, 16, 16], [8, 8, 8], lo, hi, [.false., .false., .false.], &
      .false.)
    column_rank = [(ib * np / 4, ib = 0, 3)]
    lay%owner = [(column_rank(mod(id - 1, 4)), id = 1, lay%nblocks)]
    call blocks_allocate(lay, me, 3, blocks)
    call halo_plan_build(lay, blocks, plan)
    cuts = 0
    copy_cells = 0
    do ib = 1, 3
      if (column_rank(ib - 1) /= column_rank(ib) .and. &
        (column_rank(ib - 1) == me .or. column_rank(ib) == me)) cuts = cuts + 1
    end do
    do ib = 0, 3
      if (column_rank(ib) /= me) cycle
      foreign = count(column_rank(max(ib - 1, 0):min(ib + 1, 3)) /= me)
      copy_cells = copy_cells + 4 * (merge(1216, 1792, ib == 0 .or. ib == 3) - 576 * foreign)
    end do
    call halo_exchange(plan, blocks, 3)
    call halo_exchange(plan, blocks, 3, first=3)
    write(text, '(a,i0,a,i0,a)') 'counts on rank ', me, ' of ', np, ' (slabs of 4 x 2 x 2 blocks)'
    call check(trim(text) // ': exchanges', plan%counts%exchanges == 2)
    call check(trim(text) // ': one message per cut and exchange', &
      plan%counts%messages == 2 * cuts)
    call check(trim(text) // ': bytes sent', &
      plan%counts%bytes == int(wp_bytes * 2304 * cuts * (3 + 1), i8))
    call check(trim(text) // ': bytes copied on the rank', &
      plan%counts%copy_bytes == int(wp_bytes * copy_cells * (3 + 1), i8))
  end subroutine count_case

  subroutine fill_interior(blocks, shift)
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: shift
    integer :: b, i, j, k, m
    do b = 1, size(blocks)
      do m = 1, 3
        do k = 1, blocks(b)%n(3)
          do j = 1, blocks(b)%n(2)
            do i = 1, blocks(b)%n(1)
              blocks(b)%q(i, j, k, m) = code(blocks(b)%offset + [i, j, k], m) + shift
            end do
          end do
        end do
      end do
    end do
  end subroutine fill_interior

    ! every halo cell with a source block holds its source's code plus shift, except in a
    ! skipped block, variables 1-2, from a block of this rank: the code of before (shift 0)
  subroutine check_halos(lay, blocks, skip, shift)
    type(layout_t), intent(in) :: lay
    type(block_t), intent(in) :: blocks(:)
    logical, intent(in) :: skip(:)
    real(wp), intent(in) :: shift
    integer :: b, i, j, k, m, g(3), dir(3), nbr, d, checked, nbad
    real(wp) :: expect
    character(len=120) :: first
    checked = 0
    nbad = 0
    first = ''
    do b = 1, size(blocks)
      do k = 1 - lay%ng(3), blocks(b)%n(3) + lay%ng(3)
        do j = 1 - lay%ng(2), blocks(b)%n(2) + lay%ng(2)
          do i = 1 - lay%ng(1), blocks(b)%n(1) + lay%ng(1)
            dir = 0
            g = [i, j, k]
            do d = 1, 3
              if (g(d) < 1) dir(d) = -1
              if (g(d) > blocks(b)%n(d)) dir(d) = 1
            end do
            if (all(dir == 0)) cycle
            nbr = block_neighbor(lay, blocks(b)%id, dir)
            if (nbr <= 0) cycle
            g = blocks(b)%offset + [i, j, k]
            do d = 1, 3
              g(d) = modulo(g(d) - 1, lay%cells(d)) + 1
            end do
            do m = 1, 3
              checked = checked + 1
              expect = code(g, m) + shift
              if (skip(b) .and. m < 3 .and. lay%owner(nbr) == comm_rank()) expect = code(g, m)
              if (abs(blocks(b)%q(i, j, k, m) - expect) > 0.0_wp) then
                if (nbad == 0) write(first, '(a,3i4,a,i0,a,i0,a,2es14.6)') ', first: cell ', &
                  i, j, k, ' of block ', blocks(b)%id, ' variable ', m, ': got/expected ', &
                  blocks(b)%q(i, j, k, m), expect
                nbad = nbad + 1
              end if
            end do
          end do
        end do
      end do
    end do
    call check(trim(lay_text(lay)) // ': every halo cell holds its source''s value' // &
      trim(first), nbad == 0)
    call check(trim(lay_text(lay)) // ': some halo cells checked', comm_sum(int(checked, i8)) > 0)
  end subroutine check_halos

  !> The case in words for the messages: dimensions, cells and blocks.
  function lay_text(lay) result(t)
    type(layout_t), intent(in) :: lay
    character(len=64) :: t
    write(t, '(i0,a,3(1x,i0),a,3(1x,i0))') lay%ndim, 'D, cells', lay%cells, ', blocks', &
      lay%bsize
  end function lay_text

end program test_halo
