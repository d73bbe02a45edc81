!> The XDMF 3 companion of a plot file (DESIGN section 7): a small XML file, written by rank 0
!> beside plot_NNNNNN.h5, that lets ParaView and VisIt open the global fields directly. The
!> mesh is a 3DCoRectMesh (uniform, axis-aligned) of cells(3)+1 x cells(2)+1 x cells(1)+1
!> nodes; XDMF lists dimensions slowest first, and the ORIGIN_DXDYDZ geometry lists origin and
!> spacing in the same z, y, x order (readers reverse both to get x, y, z). Each field is a
!> cell-centred scalar pointing at h5_name:/fields/<name>, a float64 dataset that C and h5py
!> see as (nz, ny, nx). 1D and 2D runs give a mesh one cell thick in the unused directions.
!> This module writes only XML: the HDF5 side is m_hdf5_io's.
module m_xdmf
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_comm, only: comm_is_root
  use m_errors, only: fatal
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
    integer :: u, ios, n
    if (.not. comm_is_root()) return
    node_dims = dims_text(lay%cells(3:1:-1) + 1)
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
    write(u, '(a)') '          ' // real_text(lay%lo(3)) // ' ' // real_text(lay%lo(2)) // &
      ' ' // real_text(lay%lo(1))
    write(u, '(a)') '        </DataItem>'
    write(u, '(a)') '        <DataItem Name="Spacing" Dimensions="3" NumberType="Float" ' // &
      'Precision="8" Format="XML">'
    write(u, '(a)') '          ' // real_text(lay%dx(3)) // ' ' // real_text(lay%dx(2)) // &
      ' ' // real_text(lay%dx(1))
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

  !> A real with every bit of precision, so the mesh sits exactly where the solver's is.
  pure function real_text(x) result(s)
    real(wp), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=32) :: buf
    write(buf, '(es24.16e3)') x
    s = trim(adjustl(buf))
  end function real_text

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
