!> The a-posteriori fallback (manual/theory.md section 3) and the step's counters. Nothing is
!> clipped: a cell the update leaves inadmissible (rho <= 0, c^2 <= 0 or not finite) is
!> recomputed, not repaired.
!> - cell-local: find_trouble marks the interior cells of a block that hold no admissible
!>   state for some phase; the caller redoes the block's stage with every face of those
!>   cells at first order (conservative: both neighbours see the same face flux). A trouble
!>   cell on a side the block shares with another block is left to the step fallback.
!> - step: when a step leaves any cell inadmissible on any rank, fallback_step recomputes
!>   the whole step from its start at first order in space (eno1 + LLF, same Runge-Kutta,
!>   fallback_numerics), and if that is still inadmissible with dt halved, up to four times.
!>   Every rank takes the same decision, so results stay bit-identical on any number of
!>   ranks; run.log and history.csv (first_order_steps) say how often it was needed.
module m_fallback
  use m_kinds, only: wp, i8, line_len
  use m_layout, only: layout_t
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_eos, only: eos_sound_speed2
  use m_elastoplastic, only: primitive_row
  use m_euler, only: numerics_t
  use m_reconstruct, only: scheme_eno1
  use m_flux, only: flux_kind_llf
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en
  use m_errors, only: log_line
  implicit none
  private
  public :: counters_t, find_trouble, fallback_numerics, fallback_step, redo_step

  !> What the step had to do to survive, and its cost (this rank's unless said otherwise)
  type :: counters_t
    integer(i8) :: cell_steps = 0      !< cells x steps, for the cost report
    integer(i8) :: fallback_faces = 0  !< faces reconstructed at first order
    integer(i8) :: fallback_step = 0   !< the same, in the last step, summed over ranks
    integer :: first_order_steps = 0   !< steps recomputed at first order (a-posteriori)
    integer(i8) :: cells_low = 0       !< cells redone with first-order faces
    logical :: step_failed = .false.   !< the last step met a state with no admissible cells
  end type counters_t

  abstract interface
    !> The step of the simulation sim from its start again with time step dt at first order;
    !> ok: every cell of every rank admissible after it.
    subroutine redo_step(sim, dt, ok)
      import :: wp
      class(*), intent(inout) :: sim
      real(wp), intent(in) :: dt
      logical, intent(out) :: ok
    end subroutine redo_step
  end interface

contains

  !> The numerics of a step recomputed by the step fallback.
  pure function fallback_numerics(num) result(low)
    type(numerics_t), intent(in) :: num
    type(numerics_t) :: low
    low = num
    low%scheme = scheme_eno1
    low%flux = flux_kind_llf
  end function fallback_numerics

  !> The step fallback for step number `step` of size dt of the simulation sim: redo (the
  !> caller's) at first order, halving dt up to four times until ok; `count` is how many
  !> steps it has recomputed with this one (the first ten are logged).
  subroutine fallback_step(sim, step, dt, count, redo, ok)
    class(*), intent(inout) :: sim
    integer, value :: step, count
    real(wp), value :: dt
    procedure(redo_step) :: redo
    logical, intent(out) :: ok
    integer :: halvings
    character(len=line_len) :: msg
    ok = .false.
    do halvings = 0, 4
      if (halvings > 0) dt = 0.5_wp * dt
      call redo(sim, dt, ok)
      if (ok) exit
    end do
    if (count > 10) return
    write(msg, '(a,i0,a,i0,a)') 'fallback: step ', step, &
      ' recomputed at first order in space (eno1 + llf), dt halved ', min(halvings, 4), ' times'
    if (.not. ok) msg = trim(msg) // ': still inadmissible'
    call log_line(msg)
  end subroutine fallback_step

  !> The interior cells of block blk that hold no admissible state for some phase (rho <= 0,
  !> c^2 <= 0 or not finite) into trouble; edge is true when one lies on a side the block
  !> shares with another block (lay: the whole grid's layout).
  subroutine find_trouble(lay, ph, blk, trouble, nbad, edge, content)
    type(layout_t), intent(in) :: lay
    type(phases_t), intent(in) :: ph
    type(block_t), intent(in) :: blk
    logical, intent(out) :: trouble(:, :, :)
    integer, intent(out) :: nbad
    logical, intent(out) :: edge
    !> the phases whose variables hold their cut-cell content, not states (m_gfm_cut; 0:
    !> none): their states are tested when they are made
    integer, intent(in) :: content(:)
    integer :: j, k, p, off, n, d
    logical :: lo_shared, hi_shared
    real(wp), dimension(blk%n(1)) :: rho, u, v, w, pr, e, c2
    n = blk%n(1)
    trouble = .false.
    associate (q => blk%q)
      do p = 1, ph%nphase
        if (any(content == p)) cycle
        off = ph%lo(p) - 1
        do k = 1, blk%n(3)
          do j = 1, blk%n(2)
            rho = q(1:n, j, k, off + i_rho)
            if (all(rho > 0.0_wp .and. abs(q(1:n, j, k, off + i_en)) <= huge(1.0_wp))) then
              call primitive_row(ph%eos(p), n, q(1:n, j, k, off + i_rho), &
                q(1:n, j, k, off + i_mx), q(1:n, j, k, off + i_my), q(1:n, j, k, off + i_mz), &
                q(1:n, j, k, off + i_en), rho, u, v, w, pr, e)
              call eos_sound_speed2(ph%eos(p), n, rho, pr, c2)
              if (all(c2 > 0.0_wp .and. c2 <= huge(1.0_wp))) cycle
              trouble(:, j, k) = trouble(:, j, k) .or. .not. (c2 > 0.0_wp .and. c2 <= huge(1.0_wp))
            else
              trouble(:, j, k) = trouble(:, j, k) .or. .not. (rho > 0.0_wp)
              trouble(:, j, k) = trouble(:, j, k) .or. &
                .not. abs(q(1:n, j, k, off + i_en)) <= huge(1.0_wp)
            end if
          end do
        end do
      end do
    end associate
    nbad = count(trouble)
    edge = .false.
    if (nbad == 0) return
    ! a side shared with another block (not a domain side, unless periodic)
    associate (off3 => blk%offset, nb => blk%n)
      do d = 1, lay%ndim
        lo_shared = off3(d) > 0 .or. lay%periodic(d)
        hi_shared = off3(d) + nb(d) < lay%cells(d) .or. lay%periodic(d)
        select case (d)
        case (1)
          edge = edge .or. (lo_shared .and. any(trouble(1, :, :))) .or. &
            (hi_shared .and. any(trouble(nb(1), :, :)))
        case (2)
          edge = edge .or. (lo_shared .and. any(trouble(:, 1, :))) .or. &
            (hi_shared .and. any(trouble(:, nb(2), :)))
        case default
          edge = edge .or. (lo_shared .and. any(trouble(:, :, 1))) .or. &
            (hi_shared .and. any(trouble(:, :, nb(3))))
        end select
      end do
    end associate
  end subroutine find_trouble

end module m_fallback
