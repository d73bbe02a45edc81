!> How the level sets of a block move in a Runge-Kutta stage (manual/interfaces.md section
!> 1): a material body moves with its phase's velocity (extended into the ghost band by the
!> ghost fill, so it is an extension velocity there), a void body with the velocity of the
!> phase nearest to each cell, inside the narrow band |phi| <= band dx; rigid ones are set
!> to the stage time by the scene (m_scene) and have no rate. Kernels only: no MPI, no I/O.
module m_levelset_motion
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_mx, i_mz
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_rigid, ls_material
  use m_levelset_advect, only: levelset_advect_rhs
  implicit none
  private
  public :: levelset_rates

contains

  !> The rates of block blk's level sets into blk%rhs; lay is the grid's layout, band the
  !> narrow band in cells; vel (padded block, 3), ls_rhs (block), bigphi and owner (padded
  !> block, phase) are work space.
  subroutine levelset_rates(lay, ls, ph, band, blk, vel, ls_rhs, bigphi, owner)
    type(layout_t), intent(in) :: lay
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: band
    type(block_t), intent(inout) :: blk
    real(wp), intent(inout) :: vel(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(inout) :: ls_rhs(:, :, :)
    real(wp), intent(inout) :: bigphi(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    integer, intent(inout) :: owner(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    integer :: l, iv, p
    real(wp) :: width
    associate (q => blk%q, rhs => blk%rhs, n => blk%n)
      width = real(band, wp) * maxval(lay%dx(1:lay%ndim))
      p = -1
      do l = 1, ls%n
        iv = ph%ils + l
        if (ls%kind(l) == ls_rigid) then
          rhs(:, :, :, iv) = 0.0_wp
          cycle
        end if
        if (ls%kind(l) == ls_material) then
          if (ls%phase(l) /= p) call phase_velocity(ls%phase(l))
          p = ls%phase(l)
        else
          if (p /= 0) call phase_velocity(0)
          p = 0
        end if
        call levelset_advect_rhs(lay%ndim, n, lay%ng, lay%dx, q(:, :, :, iv), vel, ls_rhs)
        where (abs(q(1:n(1), 1:n(2), 1:n(3), iv)) > width) ls_rhs = 0.0_wp
        rhs(:, :, :, iv) = ls_rhs
      end do
    end associate

  contains

    !> vel on the padded block: the velocity of phase pp, or for pp = 0 of the phase whose
    !> composite level set is least at each cell (the phase there, or the nearest one).
    subroutine phase_velocity(pp)
      integer, intent(in) :: pp
      integer :: d, m, off, lo(3), hi(3), i, j, k
      associate (q => blk%q)
        if (pp > 0 .or. ph%nphase == 1) then
          off = ph%lo(max(pp, 1)) - 1
          do d = 1, 3
            vel(:, :, :, d) = q(:, :, :, off + i_mx + d - 1) / q(:, :, :, off + i_rho)
          end do
          return
        end if
        lo = 1 - lay%ng
        hi = blk%n + lay%ng
        do m = 1, ph%nphase
          call ls_region(ls, m, lo, hi, q(:, :, :, ph%ils + 1:ph%nvar), bigphi(:, :, :, m), &
            owner(:, :, :, m))
        end do
        do k = lo(3), hi(3)
          do j = lo(2), hi(2)
            do i = lo(1), hi(1)
              off = ph%lo(minloc(bigphi(i, j, k, :), 1)) - 1
              vel(i, j, k, :) = q(i, j, k, off + i_mx:off + i_mz) / q(i, j, k, off + i_rho)
            end do
          end do
        end do
      end associate
    end subroutine phase_velocity

  end subroutine levelset_rates

end module m_levelset_motion
