!> MVI, the material-void boundary class (DESIGN section 1, manual/interfaces.md section 2):
!> a traction-free surface. From the image state wi at IP1 the ghost takes the density,
!> pressure, plastic strain, stored work and velocity (extended), the tangential stresses
!> (extended) and the normal stress and normal shears reversed, so that sigma . n = 0 on the
!> surface (m_gfm_stress, with the J1 correction).
!> A fluid (no stress) has no tension to reverse: its ghost is the extended image state, a
!> zero-gradient free boundary.
module m_gfm_mvi
  use m_kinds, only: wp
  use m_gfm_stress, only: reflect_stress
  use m_state, only: n_solid
  implicit none
  private
  public :: gfm_mvi

contains

  pure subroutine gfm_mvi(ndim, nrm, wi, wg)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: nrm(3)   !< unit normal, out of the material
    real(wp), intent(in) :: wi(:)    !< primitive state at the image point
    real(wp), intent(out) :: wg(:)   !< ghost state
    wg = wi
    if (size(wi) >= n_solid) call reflect_stress(ndim, nrm, wi, .true., wg)
  end subroutine gfm_mvi

end module m_gfm_mvi
