!> MRI, the material-rigid boundary class (DESIGN section 1, manual/interfaces.md section 2):
!> a frictionless rigid wall moving at velocity vb. The ghost's normal velocity is the mirror
!> about the wall's, 2 vb.n - u.n, its tangential velocity is extended (free slip); density,
!> plastic strain and stored work are extended; the normal stress is continuous (kept) and
!> the normal shears are reversed (no shear traction).
module m_gfm_mri
  use m_kinds, only: wp
  use m_gfm_stress, only: reflect_stress
  use m_state, only: n_solid
  implicit none
  private
  public :: gfm_mri

contains

  pure subroutine gfm_mri(ndim, nrm, vb, wi, wg)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: nrm(3)   !< unit normal, out of the material (into the wall)
    real(wp), intent(in) :: vb(3)    !< the wall's velocity
    real(wp), intent(in) :: wi(:)    !< primitive state at the image point
    real(wp), intent(out) :: wg(:)   !< ghost state
    wg = wi
    wg(2:4) = wi(2:4) + 2.0_wp * dot_product(vb - wi(2:4), nrm) * nrm
    if (size(wi) >= n_solid) call reflect_stress(ndim, nrm, wi, .false., wg)
  end subroutine gfm_mri

end module m_gfm_mri
