!> MMI, the material-material boundary class (DESIGN section 1, manual/interfaces.md
!> section 2): two phases in contact, normal velocity and normal stress continuous,
!> tangential components extended (frictionless slip). The interface state comes from the
!> acoustic Riemann problem along the normal between the image state wi of this phase
!> (at IP1, a distance Phi inside it) and the partner's state wk (at the ghost cell itself,
!> a distance Phi inside the partner):
!>   P* = (Z_k P_i + Z_i P_k + Z_i Z_k (u_i - u_k)) / (Z_i + Z_k),
!>   u* = (Z_i u_i + Z_k u_k + P_i - P_k) / (Z_i + Z_k),
!> with u the velocity along n (out of this phase), P = p - S_nn the normal compression and
!> Z = rho c_L the impedance. The ghost then
!> - of a phase with strength: takes the normal velocity mirrored about u*, and the normal
!>   stress reflected about -P* in its deviator, S'_nn -> 2 (p - P*) - S'_nn (P* = 0 is the
!>   traction-free MVI), shears reversed, J1 restored (m_gfm_stress); rho and p extended;
!> - of a fluid: is the interface state on its side (the real ghost fluid method of Wang,
!>   Liu and Khoo 2006): u.n = u*, p = P*, rho on the linearised isentrope through the image.
!> Bodies in contact cannot pull on each other: where P* <= 0 between two bodies the caller
!> treats the ghost as a free surface (separated = .true.).
module m_gfm_mmi
  use m_kinds, only: wp
  use m_gfm_stress, only: reflect_stress
  use m_state, only: n_solid
  implicit none
  private
  public :: gfm_mmi

  integer, parameter :: ip = 5, is = 6

contains

  pure subroutine gfm_mmi(ndim, nrm, wi, wk, zi, zk, c2i, strength, wg, pstar)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: nrm(3)   !< unit normal, out of this phase (into the partner)
    real(wp), intent(in) :: wi(:)    !< primitive state of this phase at the image point
    real(wp), intent(in) :: wk(:)    !< primitive state of the partner across the surface
    real(wp), intent(in) :: zi, zk   !< impedances rho c_L of the two states
    real(wp), intent(in) :: c2i      !< squared bulk sound speed of wi
    logical, intent(in) :: strength  !< this phase carries a deviatoric stress
    real(wp), intent(out) :: wg(:)   !< ghost state
    real(wp), intent(out) :: pstar   !< normal compression at the interface
    real(wp) :: ui, uk, pi, pk, ustar, snn(2), g(3)
    ui = dot_product(wi(2:4), nrm)
    uk = dot_product(wk(2:4), nrm)
    snn = 0.0_wp
    if (size(wi) >= n_solid) snn(1) = normal_deviator(wi)
    if (size(wk) >= n_solid) snn(2) = normal_deviator(wk)
    pi = wi(ip) - snn(1)
    pk = wk(ip) - snn(2)
    pstar = (zk * pi + zi * pk + zi * zk * (ui - uk)) / (zi + zk)
    ustar = (zi * ui + zk * uk + pi - pk) / (zi + zk)
    wg = wi
    if (strength) then
      wg(2:4) = wi(2:4) + 2.0_wp * (ustar - ui) * nrm
      g = nrm
      call reflect_stress(ndim, g, shifted(wi, wi(ip) - pstar), .true., wg)
      wg(ip) = wi(ip)
    else
      wg(2:4) = wi(2:4) + (ustar - ui) * nrm
      wg(ip) = pstar
      wg(1) = max(wi(1) + (pstar - wi(ip)) / c2i, 0.1_wp * wi(1))
    end if

  contains

    !> the normal component n.S.n of a state's deviator
    pure real(wp) function normal_deviator(w) result(s)
      real(wp), intent(in) :: w(:)
      s = w(is) * nrm(1)**2 + w(is+1) * nrm(2)**2 + w(is+2) * nrm(3)**2 &
        + 2.0_wp * (w(is+3) * nrm(1) * nrm(2) + w(is+4) * nrm(2) * nrm(3) &
        + w(is+5) * nrm(1) * nrm(3))
    end function normal_deviator

  end subroutine gfm_mmi

  !> wi with its pressure slot replaced by ps: reflect_stress reflects S'_nn about that value
  pure function shifted(w, ps) result(v)
    real(wp), intent(in) :: w(:), ps
    real(wp) :: v(size(w))
    v = w
    v(ip) = ps
  end function shifted

end module m_gfm_mmi
