!> The conservation fix of the ghost-fluid method (manual/interfaces.md section 2b). The
!> ghost-fluid update is not conservative where a surface moves: a cell that turns real takes
!> a ghost state, a cell that stops being real takes its content with it, and the faces
!> between real cells and ghosts carry fluxes computed with ghost states. After each step the
!> caller (m_timeloop) measures the mass and total energy of each solid phase over its real
!> cells, compares them with targets (the run's start plus what came in through the domain's
!> sides), and returns what lies beyond a band to the phase's surface cells (real, within
!> `width` of the surface):
!> - mass: every conserved variable of those cells is scaled by one factor, so velocity,
!>   specific energy, deviatoric stress and plastic strain are unchanged;
!> - energy (over all solid phases together, when nothing outside them can do work on them):
!>   an excess is taken from the internal energy in proportion to each cell's share of it
!>   (the caller says how much; the rest in proportion to mass), a deficit is added to the
!>   internal energy in proportion to mass.
!> Kernels on one block; no MPI, no I/O.
module m_gfm_conserve
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_state, only: i_rho, i_mx, i_mz, i_en
  implicit none
  private
  public :: content_block, fix_block

  !> per phase and block: mass, energy, surface mass, surface energy, surface internal energy
  integer, parameter, public :: n_content = 5

contains

  !> Internal energy per volume, rho E - |rho u|^2 / (2 rho), of one cell.
  pure real(wp) function heat(qc) result(h)
    real(wp), intent(in) :: qc(:)
    h = qc(i_en) - 0.5_wp * sum(qc(i_mx:i_mz)**2) / qc(i_rho)
  end function heat

  !> The content c of one phase over the interior cells of a block: q holds the phase's
  !> conserved variables, bigphi its composite level set (< 0: real). A cell counts with the
  !> fraction f = min(1, max(0, 1/2 - Phi / h)) of its volume, as the bodies' masses of
  !> history.csv do (m_output), so that the measure follows the surface smoothly rather than
  !> by whole cells. A cell just outside the surface (0 <= Phi < h / 2) holds the rest state
  !> after a step; its share is taken at the state of its real face neighbour deepest in the
  !> material (in this block), which the fix moves with the surface cells, so that a fix
  !> changes the measure by exactly what it says; with no such neighbour in the block, at
  !> its own density and no energy.
  pure subroutine content_block(lay, offset, q, bigphi, h, width, c)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3)
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp), intent(in) :: h, width
    real(wp), intent(out) :: c(n_content)
    real(wp) :: dv(lay%bsize(1)), f
    integer :: i, j, k, s(3)
    dv = [(cell_volume(lay, offset, i), i = 1, lay%bsize(1))]
    c = 0.0_wp
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          if (.not. bigphi(i, j, k) < 0.5_wp * h) cycle
          f = min(1.0_wp, 0.5_wp - bigphi(i, j, k) / h) * dv(i)
          s = [i, j, k]
          if (bigphi(i, j, k) >= 0.0_wp) s = deepest(i, j, k)
          if (s(1) == 0) then
            c(1) = c(1) + f * q(i, j, k, i_rho)
            cycle
          end if
          c(1) = c(1) + f * q(s(1), s(2), s(3), i_rho)
          c(2) = c(2) + f * q(s(1), s(2), s(3), i_en)
          if (bigphi(s(1), s(2), s(3)) < -width) cycle
          c(3) = c(3) + f * q(s(1), s(2), s(3), i_rho)
          c(4) = c(4) + f * q(s(1), s(2), s(3), i_en)
          c(5) = c(5) + f * max(heat(q(s(1), s(2), s(3), :)), 0.0_wp)
        end do
      end do
    end do

  contains

    !> the real face neighbour of (i0, j0, k0) in the block interior with the least Phi
    !> ([0, 0, 0] if none)
    pure function deepest(i0, j0, k0) result(t)
      integer, intent(in) :: i0, j0, k0
      integer :: t(3), d, sg, u(3)
      real(wp) :: best
      t = 0
      best = 0.0_wp
      do d = 1, lay%ndim
        do sg = -1, 1, 2
          u = [i0, j0, k0]
          u(d) = u(d) + sg
          if (u(d) < 1 .or. u(d) > lay%bsize(d)) cycle
          if (bigphi(u(1), u(2), u(3)) < best) then
            best = bigphi(u(1), u(2), u(3))
            t = u
          end if
        end do
      end do
    end function deepest

  end subroutine content_block

  !> Apply the fix to the surface cells of one phase on a block: scale every conserved
  !> variable by fm, then add a_heat times the (non-negative) internal energy and a_mass times
  !> the density to rho E.
  pure subroutine fix_block(lay, q, bigphi, width, fm, a_heat, a_mass)
    type(layout_t), intent(in) :: lay
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):)
    real(wp), intent(in) :: width, fm, a_heat, a_mass
    integer :: i, j, k
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          if (.not. (bigphi(i, j, k) < 0.0_wp .and. bigphi(i, j, k) >= -width)) cycle
          q(i, j, k, :) = fm * q(i, j, k, :)
          q(i, j, k, i_en) = q(i, j, k, i_en) + a_heat * max(heat(q(i, j, k, :)), 0.0_wp) &
            + a_mass * q(i, j, k, i_rho)
        end do
      end do
    end do
  end subroutine fix_block

end module m_gfm_conserve
