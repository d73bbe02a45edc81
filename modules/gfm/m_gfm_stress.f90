!> The deviatoric stress of a ghost state in the local frame of an interface, shared by the
!> boundary classes (manual/interfaces.md section 2). Primitive states are (rho, u, v, w, p,
!> S_xx, S_yy, S_zz, S_xy, S_yz, S_xz, eps_p, w_c), S the deviatoric stress, as in m_euler's
!> prim; a fluid state stops at p.
!> The ghost keeps the image's thermodynamic state (rho and p, hence e: no energy is pulled out
!> of the surface cells by the flux's dissipation). In the frame (n, t1, t2), t2 the
!> out-of-plane direction in 2D, S' = R S R^T with rows n, t1, t2:
!> - the normal shears S'_nt1, S'_nt2 are reversed (no shear traction);
!> - traction-free (MVI): sigma'_nn = -p + S'_nn is reversed, S'_nn -> 2 p - S'_nn; the
!>   trace this leaves is taken out of the out-of-plane component S'_t2t2 in 2D (the hoop
!>   stress in axisymmetry), of S'_t1t1 and S'_t2t2 in equal parts in 3D, so that
!>   J1 = tr S = 0 holds in the ghost;
!> - continuous normal stress (MRI): S'_nn is kept, and the trace is unchanged.
!> Then S = R^T S' R.
module m_gfm_stress
  use m_kinds, only: wp
  implicit none
  private
  public :: reflect_stress, cross_product

  integer, parameter :: ip = 5, is = 6   !< positions of p and S_xx in a primitive state

contains

  !> wg(is:is+5) from wi in a space of ndim dimensions.
  pure subroutine reflect_stress(ndim, nrm, wi, flip_normal, wg)
    integer, intent(in) :: ndim
    real(wp), intent(in) :: nrm(3), wi(:)
    logical, intent(in) :: flip_normal
    real(wp), intent(inout) :: wg(:)
    real(wp) :: s(3, 3), r(3, 3), t1(3), t2(3), tr
    s = reshape([wi(is), wi(is+3), wi(is+5), wi(is+3), wi(is+1), wi(is+4), &
      wi(is+5), wi(is+4), wi(is+2)], [3, 3])
    if (ndim < 3) then
      t2 = [0.0_wp, 0.0_wp, 1.0_wp]
    else if (abs(nrm(3)) < 0.9_wp) then
      t2 = cross_product([0.0_wp, 0.0_wp, 1.0_wp], nrm)
    else
      t2 = cross_product([1.0_wp, 0.0_wp, 0.0_wp], nrm)
    end if
    t2 = t2 / norm2(t2)
    t1 = cross_product(t2, nrm)
    r(1, :) = nrm
    r(2, :) = t1
    r(3, :) = t2
    s = matmul(r, matmul(s, transpose(r)))
    s(1, 2:3) = -s(1, 2:3)
    s(2:3, 1) = -s(2:3, 1)
    if (flip_normal) then
      s(1, 1) = 2.0_wp * wi(ip) - s(1, 1)
      tr = s(1, 1) + s(2, 2) + s(3, 3)
      if (ndim < 3) then
        s(3, 3) = s(3, 3) - tr
      else
        s(2, 2) = s(2, 2) - 0.5_wp * tr
        s(3, 3) = s(3, 3) - 0.5_wp * tr
      end if
    end if
    s = matmul(transpose(r), matmul(s, r))
    wg(ip) = wi(ip)
    wg(is) = s(1, 1)
    wg(is+1) = s(2, 2)
    wg(is+2) = s(3, 3)
    wg(is+3) = s(1, 2)
    wg(is+4) = s(2, 3)
    wg(is+5) = s(1, 3)
  end subroutine reflect_stress

  !> a x b (also the unit tests' cross product)
  pure function cross_product(a, b) result(c)
    real(wp), intent(in) :: a(3), b(3)
    real(wp) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross_product

end module m_gfm_stress
