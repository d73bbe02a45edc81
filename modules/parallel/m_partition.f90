!> Distribution of blocks over ranks (DESIGN section 3): METIS_PartGraphKway on the graph of
!> active blocks, edges between face neighbours weighted by the face area in cells, vertex
!> weights = work of the block. Rank 0 partitions and broadcasts the owner of every block,
!> so every rank holds the same map. The first partition (partition_blocks) is made from an
!> estimate of the work; a re-partition (partition_owner, m_rebalance) from the work the
!> blocks were measured to do. Knows nothing of physics.
module m_partition
  use, intrinsic :: iso_c_binding, only: c_int32_t, c_ptr, c_null_ptr, c_int
  use m_kinds, only: wp
  use m_layout, only: layout_t, block_neighbor, block_extent
  use m_comm, only: comm_is_root, comm_bcast, comm_size
  use m_errors, only: stop_collective
  implicit none
  private
  public :: partition_blocks, partition_owner

  interface
    integer(c_int) function metis_partgraphkway(nvtxs, ncon, xadj, adjncy, vwgt, vsize, &
        adjwgt, nparts, tpwgts, ubvec, options, objval, part) bind(C, name='METIS_PartGraphKway')
      import :: c_int32_t, c_ptr, c_int
      integer(c_int32_t), intent(in) :: nvtxs, ncon, nparts
      integer(c_int32_t), intent(in) :: xadj(*), adjncy(*), vwgt(*), adjwgt(*)
      type(c_ptr), value :: vsize, tpwgts, ubvec, options
      integer(c_int32_t), intent(out) :: objval
      integer(c_int32_t), intent(out) :: part(*)
    end function metis_partgraphkway
  end interface

contains

  !> Fill lay%owner for every active block (inactive blocks get -1); work(id) >= 1.
  subroutine partition_blocks(lay, work)
    type(layout_t), intent(inout) :: lay
    integer, intent(in) :: work(:)
    integer :: nparts, nact
    integer, allocatable :: owner(:)
    nparts = comm_size()
    nact = count(lay%active)
    call stop_collective('ERROR &domain block: ' // trim(itoa(nact)) // ' active blocks for ' &
      // trim(itoa(nparts)) // ' ranks; use smaller blocks or fewer ranks', nact >= nparts)
    allocate(owner(lay%nblocks))
    call partition_owner(lay, work, owner)
    lay%owner = owner
  end subroutine partition_blocks

  !> owner(id) of every block for the weights work(id) >= 1 (-1 for inactive blocks), the
  !> same on every rank (rank 0 partitions, then broadcasts); lay is left as it is.
  subroutine partition_owner(lay, work, owner)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: work(:)
    integer, intent(out) :: owner(:)
    owner = -1
    if (comm_is_root()) call partition_on_root(lay, work, comm_size(), owner)
    call comm_bcast(owner, 0)
  end subroutine partition_owner

  subroutine partition_on_root(lay, work, nparts, owner)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: work(:), nparts
    integer, intent(inout) :: owner(:)
    integer, allocatable :: vertex_of(:), block_of(:)
    integer(c_int32_t), allocatable :: xadj(:), adjncy(:), vwgt(:), adjwgt(:), part(:)
    integer(c_int32_t) :: nv, ncon, np, objval
    integer :: id, v, d, s, nbr, dir(3), ne, ierr, area, ext(3)
    allocate(vertex_of(lay%nblocks), block_of(lay%nblocks))
    vertex_of = 0
    nv = 0
    do id = 1, lay%nblocks
      if (.not. lay%active(id)) cycle
      nv = nv + 1
      vertex_of(id) = nv
      block_of(nv) = id
    end do
    if (nparts == 1) then
      where (lay%active) owner = 0
      return
    end if
    allocate(xadj(nv + 1), adjncy(6 * nv), adjwgt(6 * nv), vwgt(nv), part(nv))
    ne = 0
    xadj(1) = 0
    do v = 1, nv
      id = block_of(v)
      vwgt(v) = int(max(1, work(id)), c_int32_t)
      ext = block_extent(lay, id)
      do d = 1, lay%ndim
        ! the face's cells (the two blocks have the same extent across it)
        area = product(ext) / ext(d)
        do s = -1, 1, 2
          dir = 0
          dir(d) = s
          nbr = block_neighbor(lay, id, dir)
          if (nbr <= 0 .or. nbr == id) cycle
          if (any(adjncy(xadj(v) + 1:ne) == vertex_of(nbr) - 1)) cycle
          ne = ne + 1
          adjncy(ne) = int(vertex_of(nbr) - 1, c_int32_t)
          adjwgt(ne) = int(area, c_int32_t)
        end do
      end do
      xadj(v + 1) = int(ne, c_int32_t)
    end do
    ncon = 1
    np = int(nparts, c_int32_t)
    ierr = metis_partgraphkway(nv, ncon, xadj, adjncy, vwgt, c_null_ptr, adjwgt, np, &
      c_null_ptr, c_null_ptr, c_null_ptr, objval, part)
    if (ierr /= 1) then
      ! METIS_OK = 1; fall back to contiguous slabs of equal work rather than stop the run
      do v = 1, nv
        part(v) = int(((v - 1) * nparts) / nv, c_int32_t)
      end do
    end if
    do v = 1, nv
      owner(block_of(v)) = int(part(v))
    end do
  end subroutine partition_on_root

  pure function itoa(i) result(s)
    integer, intent(in) :: i
    character(len=16) :: s
    write(s, '(i0)') i
  end function itoa

end module m_partition
