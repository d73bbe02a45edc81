!> The XDMF 3 companion of a plot file (DESIGN section 7): a small XML file, written by rank 0
!> beside plot_NNNNNN.h5, that lets ParaView and VisIt open the global fields directly. The
!> mesh is a 3DCoRectMesh (uniform, axis-aligned); XDMF lists dimensions slowest first, and
!> the ORIGIN_DXDYDZ geometry lists origin and spacing in the same z, y, x order (readers
!> reverse both to get x, y, z). Each field is a cell-centred scalar pointing at
!> h5_name:/fields/<name>, a float64 dataset that C and h5py see as (nz, ny, nx).
!> A 2D (or axisymmetric) run is written as 2D and a 1D run as 1D: the unused directions
!> have one node (a zero-thickness extent at 0) instead of a slab one cell of the deck's
!> unused extent thick, so a viewer frames the grid itself. XDMF's own 2DCoRectMesh is not
!> used because VTK's XDMF readers place it in the y-z plane. The unused spacing is dx(1),
!> never read for bounds but kept non-zero for the filters that divide by it. Numbers are
!> written in the fewest digits that read back to the same double ("clean" spacings).
!> This module writes only XML: the HDF5 side is m_hdf5_io's.
module m_xdmf
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_comm, only: comm_is_root
  use m_errors, only: fatal
  use m_text, only: real_text
  implicit none
  private
  public :: xdmf_write

contains

  !> Write xmf_path (rank 0 only; other ranks return at once). h5_name is the plot file as
  !> the reader should find it from the .xmf, normally its bare file name.
  subroutine xdmf_write(xmf_path, h5_name, lay, names, time)
    character(len=*), intent(in) :: xmf_path, h5_name
    type(layout_t), intent(in) :: lay
    character(len=*), intent(in) :: names(:)
    real(wp), intent(in) :: time
    character(len=:), allocatable :: cell_dims, node_dims
    integer :: u, ios, n, nodes(3)
    real(wp) :: origin(3), spacing(3)
    if (.not. comm_is_root()) return
    call mesh_nodes(lay, nodes, origin, spacing)
    node_dims = dims_text(nodes(3:1:-1))
    cell_dims = dims_text(lay%cells(3:1:-1))
    open(newunit=u, file=trim(xmf_path), status='replace', action='write', iostat=ios)
    if (ios /= 0) call fatal('m_xdmf', 'cannot write ' // trim(xmf_path) // &
      ': check that out_dir exists and is writable')
    write(u, '(a)') '<?xml version="1.0" ?>'
    write(u, '(a)') '<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>'
    write(u, '(a)') '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">'
    write(u, '(a)') '  <Domain>'
    write(u, '(a)') '    <Grid Name="sabre" GridType="Uniform">'
    write(u, '(a)') '      <Time Value="' // real_text(time) // '"/>'
    write(u, '(a)') '      <Topology TopologyType="3DCoRectMesh" Dimensions="' // &
      node_dims // '"/>'
    write(u, '(a)') '      <Geometry GeometryType="ORIGIN_DXDYDZ">'
    write(u, '(a)') '        <DataItem Name="Origin" Dimensions="3" NumberType="Float" ' // &
      'Precision="8" Format="XML">'
    write(u, '(a)') '          ' // real_text(origin(3)) // ' ' // real_text(origin(2)) // &
      ' ' // real_text(origin(1))
    write(u, '(a)') '        </DataItem>'
    write(u, '(a)') '        <DataItem Name="Spacing" Dimensions="3" NumberType="Float" ' // &
      'Precision="8" Format="XML">'
    write(u, '(a)') '          ' // real_text(spacing(3)) // ' ' // real_text(spacing(2)) // &
      ' ' // real_text(spacing(1))
    write(u, '(a)') '        </DataItem>'
    write(u, '(a)') '      </Geometry>'
    do n = 1, size(names)
      write(u, '(a)') '      <Attribute Name="' // xml_escape(trim(names(n))) // &
        '" AttributeType="Scalar" Center="Cell">'
      write(u, '(a)') '        <DataItem Dimensions="' // cell_dims // &
        '" NumberType="Float" Precision="8" Format="HDF">'
      write(u, '(a)') '          ' // xml_escape(trim(h5_name)) // ':/fields/' // &
        xml_escape(trim(names(n)))
      write(u, '(a)') '        </DataItem>'
      write(u, '(a)') '      </Attribute>'
    end do
    write(u, '(a)') '    </Grid>'
    write(u, '(a)') '  </Domain>'
    write(u, '(a)', iostat=ios) '</Xdmf>'
    if (ios /= 0) call fatal('m_xdmf', 'cannot write ' // trim(xmf_path) // &
      ': is the disk full?')
    close(u)
  end subroutine xdmf_write

  !> Nodes, origin and spacing of the mesh along x, y, z: cells + 1 nodes along the run's
  !> ndim directions, one node at 0 with spacing dx(1) along the others.
  pure subroutine mesh_nodes(lay, nodes, origin, spacing)
    type(layout_t), intent(in) :: lay
    integer, intent(out) :: nodes(3)
    real(wp), intent(out) :: origin(3), spacing(3)
    nodes = 1
    origin = 0.0_wp
    spacing = lay%dx(1)
    nodes(1:lay%ndim) = lay%cells(1:lay%ndim) + 1
    origin(1:lay%ndim) = lay%lo(1:lay%ndim)
    spacing(1:lay%ndim) = lay%dx(1:lay%ndim)
  end subroutine mesh_nodes

  pure function dims_text(d) result(s)
    integer, intent(in) :: d(:)
    character(len=:), allocatable :: s
    character(len=16) :: buf
    integer :: i
    s = ''
    do i = 1, size(d)
      write(buf, '(i0)') d(i)
      if (i > 1) s = s // ' '
      s = s // trim(buf)
    end do
  end function dims_text

  !> Escape the five characters XML reserves.
  pure function xml_escape(text) result(s)
    character(len=*), intent(in) :: text
    character(len=:), allocatable :: s
    integer :: i
    s = ''
    do i = 1, len(text)
      select case (text(i:i))
      case ('&')
        s = s // '&amp;'
      case ('<')
        s = s // '&lt;'
      case ('>')
        s = s // '&gt;'
      case ('"')
        s = s // '&quot;'
      case ("'")
        s = s // '&apos;'
      case default
        s = s // text(i:i)
      end select
    end do
  end function xml_escape

end module m_xdmf
