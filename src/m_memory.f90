!> The memory a run will need (manual/user-guide.md, "Memory"): the estimate of one rank
!> in bytes, part by part, made before the grid is allocated; the resident memory then and
!> what the node has; the refusal of a run that would not fit on its node; the estimate as
!> text for run.log.
module m_memory
  use m_kinds, only: wp, i8
  use m_layout, only: layout_t
  use m_timers, only: memory_kb, node_memory_kb
  use m_comm, only: comm_size, comm_node_ranks
  use m_errors, only: stop_collective, error_line
  use m_text, only: base_name, int_text
  implicit none
  private
  public :: memory_t, mem_parts, memory_estimate, memory_check, mem_text

  !> the parts of the memory estimate (memory_estimate), in the order of memory_t%parts
  character(len=*), parameter :: mem_parts(6) = [character(len=10) :: 'state', 'halos', &
    'level_sets', 'output', 'work', 'layout']

  !> The memory estimate of one rank in bytes, part by part (mem_parts), made before the
  !> grid is allocated; the resident memory then; what the node has, and its ranks.
  type :: memory_t
    real(wp) :: parts(size(mem_parts)) = 0.0_wp
    real(wp) :: base = 0.0_wp
    real(wp) :: node_available = 0.0_wp
    integer :: node_ranks = 1
  end type memory_t

contains

  !> What one rank will hold once the grid is allocated, in bytes (manual/user-guide.md,
  !> "Memory"): the blocks' state with halo, start-of-step copy and right-hand side; the
  !> packed halo messages to other ranks (send and receive) of a compact piece of blocks;
  !> the copy of the level sets that reinitialisation keeps; one field of every block that
  !> plot files and checkpoints gather; the per-block work arrays of the fluxes and the
  !> ghost fill; the whole-grid block tables and the METIS graph. A rank is taken to hold
  !> its share of the active blocks, rounded up (METIS balances the cells).
  subroutine memory_estimate(lay, nvar, nflow, nphase, nls, mem)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: nvar, nflow, nphase   !< the state's variables, a phase's, phases
    integer, intent(in) :: nls                   !< the level sets
    type(memory_t), intent(inout) :: mem
    real(wp), parameter :: b8 = 8.0_wp
    real(wp) :: nb, ni, np, nd, halo_cells
    logical :: leader
    nd = real(lay%ndim, wp)
    nb = real(ceiling(real(count(lay%active), wp) / comm_size()), wp)
    ni = product(real(lay%nmax, wp))
    np = product(real(lay%nmax + 2 * lay%ng, wp))
    mem%parts(1) = b8 * nb * nvar * (np + 2.0_wp * ni)
    ! the blocks on the surface of a compact piece of nb blocks, one face halo each
    halo_cells = 0.0_wp
    if (comm_size() > 1) halo_cells = min(nb, 2.0_wp * nd * nb**((nd - 1.0_wp) / nd)) &
      * (np - ni) / (2.0_wp * nd)
    mem%parts(2) = 2.0_wp * b8 * nvar * halo_cells
    mem%parts(3) = b8 * nls * np * nb
    mem%parts(4) = b8 * ni * nb
    mem%parts(5) = b8 * (np * (nflow * (1 + nphase) + 2 * nphase + 3) &
      + ni * (nvar + 2))
    ! active and owner, and METIS's graph (offsets, 6 neighbours and weights, vertex
    ! weights, parts, and its own copies) of every block of the grid
    mem%parts(6) = 100.0_wp * lay%nblocks
    mem%base = 1024.0_wp * memory_kb('VmRSS')
    call comm_node_ranks(mem%node_ranks, leader)
    mem%node_available = 1024.0_wp * node_memory_kb('MemAvailable')
    if (.not. mem%node_available > 0.0_wp) &
      mem%node_available = 1024.0_wp * node_memory_kb('MemTotal')
  end subroutine memory_estimate

  !> Refuse, on every rank, a run whose ranks on one node would need more than the node has
  !> available (when the node says: /proc/meminfo).
  subroutine memory_check(mem, deck_file)
    type(memory_t), intent(in) :: mem
    character(len=*), intent(in) :: deck_file
    real(wp) :: need
    need = mem%node_ranks * sum(mem%parts)
    call stop_collective(error_line(trim(base_name(deck_file)), '&domain cells', &
      'the run needs an estimated ' // mem_text(need) // ' on this node (' &
      // int_text(mem%node_ranks) &
      // trim(merge(' rank  ', ' ranks ', mem%node_ranks == 1)) &
      // ' of ' // mem_text(sum(mem%parts)) // ' each) ' &
      // 'but the node has ' // mem_text(mem%node_available) // ' available ' &
      // '(/proc/meminfo MemAvailable): use fewer cells, or more nodes', ''), &
      .not. (mem%node_available > 0.0_wp .and. need > mem%node_available))
  end subroutine memory_check

  !> bytes with about 3 digits and a unit: '9766 GiB', '23.4 GiB', '512 MiB', '1.25 MiB'
  function mem_text(bytes) result(r)
    real(wp), intent(in) :: bytes
    character(len=:), allocatable :: r
    character(len=32) :: buf
    character(len=4) :: unit
    real(wp) :: x
    x = bytes / 1024.0_wp**3
    unit = ' GiB'
    if (x < 1.0_wp) then
      x = bytes / 1024.0_wp**2
      unit = ' MiB'
    end if
    if (x >= 100.0_wp) then
      write(buf, '(i0)') nint(x, i8)
    else if (x >= 10.0_wp) then
      write(buf, '(f0.1)') x
    else
      write(buf, '(f4.2)') x
    end if
    r = trim(adjustl(buf)) // unit
  end function mem_text

end module m_memory
