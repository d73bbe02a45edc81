!> The cut-cell phase's budget and transported scalars (issue 15, manual/interfaces.md
!> section 2c), over the state m_gfm_cut keeps: a wet cell's eps_p and w_c from its own
!> content after the ghost fill (cut_scalars), the content of a block that falls dormant
!> counted as stranded (cut_strand), and a block's mass, energy and volumes for history.csv
!> (cut_content, with the largest excess a cut cell's content hides).
module m_gfm_cut_budget
  use m_kinds, only: wp
  use m_layout, only: cell_volume
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_en, i_epsp, i_wcold
  use m_gfm_cut, only: cut_t
  use m_gfm_cut_cells, only: full
  implicit none
  private
  public :: cut_scalars, cut_strand, cut_content

contains

  !> After the ghost fill of block blk (number b) at stage `stage`: a wet cell whose centre
  !> lies outside the surface holds a ghost state for the stencils, but its transported
  !> scalars (eps_p, w_c: no traction depends on them) are those of its own content, so that
  !> what its faces carry out of it is what it holds.
  subroutine cut_scalars(cut, b, blk, ph, stage)
    type(cut_t), intent(in) :: cut
    integer, intent(in) :: b, stage
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    if (ph%nflow <= i_epsp - 1) return
    ! the first stage starts from the step's start content, the later ones from the stage's
    if (stage == 1) then
      call restore(cut%c0(:, :, :, :, b))
    else
      call restore(cut%c(:, :, :, :, b))
    end if

  contains

    subroutine restore(c)
      real(wp), intent(in) :: c(:, :, :, :)
      integer :: i, j, k, v0
      v0 = ph%lo(cut%p) - 1
      do k = 1, blk%n(3)
        do j = 1, blk%n(2)
          do i = 1, blk%n(1)
            if (.not. cut%faces(b)%alpha(i, j, k) > 0.0_wp) cycle
            if (.not. c(i, j, k, i_rho) > 0.0_wp) cycle
            blk%q(i, j, k, v0 + i_epsp:v0 + i_wcold) = blk%q(i, j, k, v0 + i_rho) &
              * c(i, j, k, i_epsp:i_wcold) / c(i, j, k, i_rho)
          end do
        end do
      end do
    end subroutine restore
  end subroutine cut_scalars

  !> A block that has fallen dormant (m_gfm: far from every surface) holds no phase: what
  !> content it still has is counted as stranded and set to zero.
  subroutine cut_strand(cut, b, blk)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(in) :: blk
    integer :: i, n(3)
    real(wp) :: dv
    n = blk%n
    do i = 1, n(1)
      dv = cell_volume(blk%lay, blk%offset, i)
      cut%out(3, b) = cut%out(3, b) + sum(cut%c(i, 1:n(2), 1:n(3), i_rho, b)) * dv
      cut%out(4, b) = cut%out(4, b) + sum(cut%c(i, 1:n(2), 1:n(3), i_en, b)) * dv
    end do
    cut%c(:, :, :, :, b) = 0.0_wp
  end subroutine cut_strand

  !> The phase's mass, total energy and volume on block b: its content at the end of the last
  !> step (sum C V), the volume its level set encloses (sum alpha V) and the volume its
  !> content fills at the density of the cells' states (sum C_rho V / rho; a wet cell with
  !> no state of its own counts alpha V), into me(1:4); and into excess the largest excess of
  !> content a cut cell holds over its fraction, C_rho / (alpha rho) - 1 over the cells with
  !> 1/2 <= alpha < 1 (a cut cell's state is at the density of the material beside it, so
  !> that is mass its pressure does not feel: theory.md 7c; small cells, which their groups
  !> mix, left out), 0 when none holds more. lo: the phase's first variable in q.
  subroutine cut_content(cut, b, blk, lo, me, excess)
    type(cut_t), intent(in) :: cut
    integer, intent(in) :: b, lo
    type(block_t), intent(in) :: blk
    real(wp), intent(out) :: me(4), excess
    integer :: i, j, k, n(3)
    real(wp) :: dv, m, rho, a
    n = blk%n
    me = 0.0_wp
    excess = 0.0_wp
    do i = 1, n(1)
      dv = cell_volume(blk%lay, blk%offset, i)
      me(1) = me(1) + sum(cut%c0(i, 1:n(2), 1:n(3), i_rho, b)) * dv
      me(2) = me(2) + sum(cut%c0(i, 1:n(2), 1:n(3), i_en, b)) * dv
      me(3) = me(3) + sum(cut%alpha_n(i, 1:n(2), 1:n(3), b)) * dv
      do k = 1, n(3)
        do j = 1, n(2)
          m = cut%c0(i, j, k, i_rho, b)
          rho = blk%q(i, j, k, lo + i_rho - 1)
          a = cut%alpha_n(i, j, k, b)
          if (m > 0.0_wp .and. rho > 0.0_wp .and. a > 0.0_wp) then
            me(4) = me(4) + m / rho * dv
            if (a >= 0.5_wp .and. a < full) excess = max(excess, m / (a * rho) - 1.0_wp)
          else
            me(4) = me(4) + a * dv
          end if
        end do
      end do
    end do
  end subroutine cut_content

end module m_gfm_cut_budget
