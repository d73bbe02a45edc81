!> The blocks a rank owns and their state arrays. A block holds the conserved variables with
!> a 4-deep halo in every active direction, q(1-ng1:n1+ng1, 1-ng2:n2+ng2, 1-ng3:n3+ng3, nvar),
!> one variable per contiguous slab (structure of arrays) so that kernels vectorise, plus the
!> start-of-step copy q0 and the right-hand side rhs over the interior only. n1, n2, n3 are
!> the block's own extent (m_layout: the last block along a direction may differ).
module m_blocks
  use m_kinds, only: wp
  use m_layout, only: layout_t, block_offset, block_extent, block_view
  implicit none
  private
  public :: block_t, blocks_allocate

  type :: block_t
    integer :: id = 0            !< global block id
    integer :: offset(3) = 0     !< local cell i is global cell offset + i
    integer :: n(3) = 1          !< its cells per direction (block_extent)
    type(layout_t) :: lay        !< the layout as the block sees it (block_view): for kernels
    real(wp), allocatable :: q(:, :, :, :)
    real(wp), allocatable :: q0(:, :, :, :)
    real(wp), allocatable :: rhs(:, :, :, :)
  end type block_t

contains

  !> Allocate the blocks this rank owns (ids in increasing order) for nvar variables.
  subroutine blocks_allocate(lay, me, nvar, blocks)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: me, nvar
    type(block_t), allocatable, intent(out) :: blocks(:)
    integer :: id, n, b, lo(3), hi(3)
    n = count(lay%owner == me .and. lay%active)
    allocate(blocks(n))
    lo = 1 - lay%ng
    b = 0
    do id = 1, lay%nblocks
      if (.not. lay%active(id) .or. lay%owner(id) /= me) cycle
      b = b + 1
      blocks(b)%id = id
      blocks(b)%offset = block_offset(lay, id)
      blocks(b)%n = block_extent(lay, id)
      blocks(b)%lay = block_view(lay, id)
      associate (n => blocks(b)%n)
        hi = n + lay%ng
        allocate(blocks(b)%q(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nvar))
        allocate(blocks(b)%q0(n(1), n(2), n(3), nvar))
        allocate(blocks(b)%rhs(n(1), n(2), n(3), nvar))
      end associate
      blocks(b)%q = 0.0_wp
      blocks(b)%q0 = 0.0_wp
      blocks(b)%rhs = 0.0_wp
    end do
  end subroutine blocks_allocate

end module m_blocks
