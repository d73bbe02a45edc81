!> The boxes of a block's cells that a mask marks, tile by tile: the block cut into tiles of
!> about `tile` cells along each direction, in each tile the smallest box that holds its
!> marked cells. The kernels that work only near a surface (m_gfm_stage's phase right-hand
!> sides, m_levelset_reinit's narrow band) compute over these boxes instead of the block.
!> A box is (low, high corner) of block cell indices; no MPI, no state.
module m_tiles
  use m_kinds, only: wp
  implicit none
  private
  public :: near_boxes, tile_cells

  !> the tiles' size in cells along each direction: within a tile the kernels compute over
  !> one box
  integer, parameter :: tile_cells = 16

contains

  !> The boxes of the true cells of mask tile by tile (none where a tile has none);
  !> boxes(:, :, ib) is (low, high corner).
  pure function near_boxes(mask, tile) result(boxes)
    logical, intent(in) :: mask(:, :, :)
    integer, intent(in) :: tile
    integer, allocatable :: boxes(:, :, :)
    integer :: nt(3), n(3), t(3), a(3), z(3), box(2, 3), nbox, i, j, k
    n = shape(mask)
    nt = max(1, nint(real(n, wp) / tile))
    allocate(boxes(2, 3, product(nt)))
    nbox = 0
    do k = 0, nt(3) - 1
      do j = 0, nt(2) - 1
        do i = 0, nt(1) - 1
          t = [i, j, k]
          a = t * n / nt + 1
          z = (t + 1) * n / nt
          box = bounding_box(mask(a(1):z(1), a(2):z(2), a(3):z(3)))
          if (any(box(1, :) > box(2, :))) cycle
          nbox = nbox + 1
          boxes(1, :, nbox) = box(1, :) + a - 1
          boxes(2, :, nbox) = box(2, :) + a - 1
        end do
      end do
    end do
    boxes = boxes(:, :, 1:nbox)
  end function near_boxes

  !> The smallest box (low, high corner) that holds every true cell of mask (low > high
  !> where it has none).
  pure function bounding_box(mask) result(box)
    logical, intent(in) :: mask(:, :, :)
    integer :: box(2, 3), d, i
    logical :: hit
    do d = 1, 3
      box(:, d) = [size(mask, d) + 1, 0]
      do i = 1, size(mask, d)
        select case (d)
        case (1)
          hit = any(mask(i, :, :))
        case (2)
          hit = any(mask(:, i, :))
        case default
          hit = any(mask(:, :, i))
        end select
        if (.not. hit) cycle
        box(1, d) = min(box(1, d), i)
        box(2, d) = i
      end do
    end do
  end function bounding_box

end module m_tiles
