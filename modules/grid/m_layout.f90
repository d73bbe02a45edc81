!> The block layout of the global grid (DESIGN section 3): how many blocks, where each one
!> sits, which rank owns it, and who its neighbours are. The grid is uniform; block ids are
!> global, 1-based, x fastest: id = 1 + ib + nb(1) * (jb + nb(2) * kb) with ib, jb, kb from 0.
!> Along each direction every block has bsize cells except the last, which holds what is
!> left: cells - (nb - 1) * bsize, between n_halo and bsize + n_halo - 1 cells (a remainder
!> thinner than the halo joins the last whole block, so that every block can fill a
!> neighbour's halo). Each block's arrays have its own extent; block_view gives a block its
!> own layout (bsize = its extent), which is what the kernels take.
!> Nothing here is of the size of the global grid: only per-block arrays. The deck's rules of
!> the cells and blocks are here too (layout_check, handed m_deck_check's rule).
module m_layout
  use m_kinds, only: wp
  use m_errors, only: rule_i
  use m_text, only: int_text, real_text, got_text
  implicit none
  private
  public :: layout_t, layout_init, block_coords, block_id, block_neighbor, block_offset
  public :: block_extent, block_view, cell_volume, active_cells, layout_blocks, layout_check
  public :: n_halo, no_neighbor, wall_neighbor

  integer, parameter :: n_halo = 4          !< halo depth in every active direction
  integer, parameter :: no_neighbor = 0     !< the domain boundary lies there
  integer, parameter :: wall_neighbor = -1  !< an inactive (rigid-obstacle) block lies there

  type :: layout_t
    integer :: ndim = 1
    integer :: cells(3) = 1          !< global cells per direction
    integer :: bsize(3) = 1          !< cells per block per direction (all but the last)
    integer :: nb(3) = 1             !< blocks per direction
    integer :: nlast(3) = 1          !< cells of the last block per direction
    integer :: nmax(3) = 1           !< largest block extent per direction
    integer :: ng(3) = 0             !< halo depth per direction (0 in inactive directions)
    integer :: nblocks = 0           !< nb(1) * nb(2) * nb(3)
    real(wp) :: lo(3) = 0.0_wp, hi(3) = 1.0_wp, dx(3) = 1.0_wp
    logical :: periodic(3) = .false.
    logical :: axisymmetric = .false.
    logical, allocatable :: active(:) !< (nblocks) false inside a rigid obstacle
    integer, allocatable :: owner(:)  !< (nblocks) rank owning the block, -1 if inactive
  end type layout_t

contains

  subroutine layout_init(lay, ndim, cells, bsize, lo, hi, periodic, axisymmetric)
    type(layout_t), intent(out) :: lay
    integer, intent(in) :: ndim, cells(3), bsize(3)
    real(wp), intent(in) :: lo(3), hi(3)
    logical, intent(in) :: periodic(3), axisymmetric
    integer :: d
    lay%ndim = ndim
    lay%cells = 1
    lay%bsize = 1
    lay%ng = 0
    lay%lo = 0.0_wp
    lay%hi = 1.0_wp
    lay%periodic = .false.
    do d = 1, ndim
      lay%cells(d) = cells(d)
      lay%bsize(d) = min(bsize(d), cells(d))
      lay%ng(d) = n_halo
      lay%lo(d) = lo(d)
      lay%hi(d) = hi(d)
      lay%periodic(d) = periodic(d)
    end do
    lay%nb = lay%cells / lay%bsize
    ! a remainder of at least the halo depth is a block of its own, a thinner one joins
    ! the last whole block
    where (mod(lay%cells, lay%bsize) >= max(lay%ng, 1)) lay%nb = lay%nb + 1
    lay%nlast = lay%cells - (lay%nb - 1) * lay%bsize
    lay%nmax = max(lay%bsize, lay%nlast)
    lay%dx = (lay%hi - lay%lo) / real(lay%cells, wp)
    lay%nblocks = product(lay%nb)
    lay%axisymmetric = axisymmetric
    allocate(lay%active(lay%nblocks), lay%owner(lay%nblocks))
    lay%active = .true.
    lay%owner = 0
  end subroutine layout_init

  !> Block coordinates (0-based) of block id.
  pure function block_coords(lay, id) result(ijk)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    integer :: ijk(3)
    ijk(1) = mod(id - 1, lay%nb(1))
    ijk(2) = mod((id - 1) / lay%nb(1), lay%nb(2))
    ijk(3) = (id - 1) / (lay%nb(1) * lay%nb(2))
  end function block_coords

  pure integer function block_id(lay, ijk)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: ijk(3)
    block_id = 1 + ijk(1) + lay%nb(1) * (ijk(2) + lay%nb(2) * ijk(3))
  end function block_id

  !> Cells of block id per direction (bsize, or nlast for the last block along it).
  !> The cells of the active blocks of the whole grid (blocks have their own extents).
  pure real(wp) function active_cells(lay) result(cells)
    type(layout_t), intent(in) :: lay
    integer :: id
    cells = 0.0_wp
    do id = 1, lay%nblocks
      if (lay%active(id)) cells = cells + real(product(block_extent(lay, id)), wp)
    end do
  end function active_cells

  pure function block_extent(lay, id) result(n)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    integer :: n(3)
    n = merge(lay%nlast, lay%bsize, block_coords(lay, id) == lay%nb - 1)
  end function block_extent

  !> The layout as block id sees it: the same grid, with bsize its own extent (what the
  !> kernels loop over and declare their arrays with), and no per-block tables (a view is
  !> for kernels, which never ask for the neighbours).
  pure function block_view(lay, id) result(v)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    type(layout_t) :: v
    v%ndim = lay%ndim
    v%cells = lay%cells
    v%bsize = block_extent(lay, id)
    v%nb = lay%nb
    v%nlast = lay%nlast
    v%nmax = lay%nmax
    v%ng = lay%ng
    v%nblocks = lay%nblocks
    v%lo = lay%lo
    v%hi = lay%hi
    v%dx = lay%dx
    v%periodic = lay%periodic
    v%axisymmetric = lay%axisymmetric
  end function block_view

  !> Global index offset of a block: its local cell i is global cell offset(1) + i.
  pure function block_offset(lay, id) result(off)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id
    integer :: off(3)
    off = block_coords(lay, id) * lay%bsize
  end function block_offset

  !> Volume of the cells of column i of a block at offset: the product of the cell sizes, times
  !> 2 pi r at the cell centre in axisymmetry (the measure of every total in history.csv).
  pure real(wp) function cell_volume(lay, offset, i) result(dv)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), i
    real(wp), parameter :: two_pi = 8.0_wp * atan(1.0_wp)
    dv = product(lay%dx(1:lay%ndim))
    if (lay%axisymmetric) dv = dv * two_pi &
      * (lay%lo(1) + (real(offset(1) + i, wp) - 0.5_wp) * lay%dx(1))
  end function cell_volume

  !> The block across offset dir (each -1, 0 or 1) from block id, with periodic wrap;
  !> no_neighbor at the domain boundary, wall_neighbor when that block is inactive.
  pure integer function block_neighbor(lay, id, dir) result(nbr)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: id, dir(3)
    integer :: ijk(3), d
    ijk = block_coords(lay, id) + dir
    do d = 1, 3
      if (ijk(d) < 0 .or. ijk(d) >= lay%nb(d)) then
        if (.not. lay%periodic(d)) then
          nbr = no_neighbor
          return
        end if
        ijk(d) = modulo(ijk(d), lay%nb(d))
      end if
    end do
    nbr = block_id(lay, ijk)
    if (.not. lay%active(nbr)) nbr = wall_neighbor
  end function block_neighbor

  !> Cells per block along a direction of n cells (manual/user-guide.md, Blocks): a target of
  !> 64 cells in 1D, 64^2 in 2D and 32^3 in 3D (the halo adds 12 %, 27 % and 95 %), n itself
  !> when n is no larger; else the largest divisor of n between half the target and the
  !> target, so that all blocks are whole, and the target itself when there is none (the
  !> last block takes the rest). Independent of the rank count, so that a deck resolves to
  !> the same blocks (and the same results) on any number of ranks. layout_blocks asks it
  !> for a block size the deck leaves at 0.
  pure integer function layout_block_size(n, nd) result(b)
    integer, intent(in) :: n, nd
    integer :: target
    target = merge(32, 64, nd == 3)
    b = n
    if (n <= target) return
    b = findloc([(mod(n, b) == 0, b = target, target / 2, -1)], .true., 1)
    b = merge(target + 1 - b, target, b > 0)
  end function layout_block_size

  !> The blocks of a domain of cells in nd dimensions as the deck gives them: 0 asks for
  !> layout_block_size; any other size goes (the last block takes what is left), one larger
  !> than the domain being the domain; 1 beyond nd.
  pure function layout_blocks(cells, block, nd) result(b)
    integer, intent(in) :: cells(3), block(3), nd
    integer :: b(3), d
    b = 1
    do d = 1, nd
      b(d) = min(block(d), cells(d))
      if (block(d) == 0) b(d) = layout_block_size(cells(d), nd)
    end do
  end function layout_blocks

  !> The deck's rules of the domain's cells, extent and blocks (m_deck_check hands its rule):
  !> at least n_halo cells along each of the first nd directions and 1 beyond, hi > lo, a
  !> block of 0 (chosen) or at least n_halo cells; then the blocks resolved (layout_blocks).
  !> cells_bad: the cells are refused already (missing, unreadable); the blocks then mean
  !> nothing and are neither checked nor resolved.
  subroutine layout_check(cells, block, lo, hi, nd, cells_bad, rule)
    integer, intent(in) :: cells(3), nd
    integer, intent(inout) :: block(3)
    real(wp), intent(in) :: lo(3), hi(3)
    logical, intent(in) :: cells_bad
    procedure(rule_i) :: rule
    character(len=:), allocatable :: nd_text, dd
    logical :: bad
    integer :: d
    nd_text = 'ndim = ' // int_text(nd)
    bad = cells_bad
    do d = 1, 3
      dd = '(' // int_text(d) // ')'
      call rule(d <= nd .and. cells(d) < n_halo, 'domain cells' // dd, &
        'must be >= 4 in a direction d <= ' // nd_text // ' (a block holds at least 4 ' &
        // 'cells: the halo is 4 deep)' // got_text(cells(d)))
      call rule(d > nd .and. cells(d) /= 1, 'domain cells' // dd, &
        'must be 1 in a direction d > ' // nd_text // got_text(cells(d)))
      bad = bad .or. (d <= nd .and. cells(d) < n_halo) .or. (d > nd .and. cells(d) /= 1)
      call rule(.not. hi(d) > lo(d), 'domain hi' // dd, 'must be > lo' // dd // ' = ' &
        // real_text(lo(d)) // got_text(hi(d)))
    end do
    if (bad) return
    ! block(d) = 0 (the default) asks for a block size chosen by layout_block_size
    do d = 1, nd
      call rule(block(d) /= 0 .and. block(d) < n_halo, 'domain block(' // int_text(d) // ')', &
        'must be >= 4 cells (the halo is 4 deep; 0 = chosen for you)' // got_text(block(d)))
    end do
    block = layout_blocks(cells, block, nd)
  end subroutine layout_check

end module m_layout
