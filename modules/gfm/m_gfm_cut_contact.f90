!> The interface exchange between two cut phases in contact (issue 15's material-material
!> interfaces, manual/theory.md section 7e): in a cell wet by both phases, the traction of
!> the contact and its work move momentum and energy from one phase's content to the
!> other's, the same amounts with opposite signs, so that what one phase loses the other
!> gains and the pair's totals change only by the fluxes through the domain's sides.
!>
!> Each phase's interface in a cell is what its wet faces leave open: by the divergence
!> theorem over the phase's part of the cell, s_k = -(sum over faces of aperture x area x
!> outward normal) / V (per unit of the cell's volume; in axisymmetry the faces r-weighted
!> and the radial part closed by the planar wet area over r, which the hoop term uses).
!> The pair shares one interface, s = (s_1 - s_2) / 2, of normal n = s / |s| (from phase 1
!> towards phase 2). The contact's normal stress P* and normal velocity u* are those of the
!> acoustic Riemann problem between the two cell states (impedances Z = rho c, normal
!> stresses P = p - n.S.n):
!>   P* = (Z2 P1 + Z1 P2 + Z1 Z2 (u1.n - u2.n)) / (Z1 + Z2),
!>   u* = (Z1 u1.n + Z2 u2.n + P1 - P2) / (Z1 + Z2).
!> Phase 1's content rate takes -P* s (momentum) and -P* u* |s| (energy), phase 2's the
!> opposite (the energy rate, times the cells' volumes, is the budget's exchange term). A
!> contact in tension (P* <= 0) exchanges nothing: the two separate, each with a
!> free surface. Frictionless: no tangential traction.
module m_gfm_cut_contact
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_solid, stress_index
  use m_eos, only: eos_t, eos_sound_speed2
  use m_elastoplastic, only: primitive_row
  use m_euler, only: cut_faces_t
  implicit none
  private
  public :: cut_contact

contains

  !> The exchange between phases 1 and 2 (their variables q1, q2 and rates r1, r2 over the
  !> padded block; geometry f1, f2 of this stage) in the cells of box (interior) wet by
  !> both. cells: how many exchanged (P* > 0); given: the energy rate phase 1 gave phase 2
  !> (times the cells' volumes, for the budget).
  subroutine cut_contact(lay, offset, box, eos1, eos2, shear1, shear2, q1, q2, f1, f2, r1, &
      r2, cells, given)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), box(2, 3)
    type(eos_t), intent(in) :: eos1, eos2
    real(wp), intent(in) :: shear1, shear2
    real(wp), intent(in) :: q1(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(in) :: q2(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(cut_faces_t), intent(in) :: f1, f2
    real(wp), intent(inout) :: r1(:, :, :, :), r2(:, :, :, :)
    integer, intent(inout) :: cells
    real(wp), intent(out) :: given
    integer :: i, j, k, d
    real(wp) :: s1(3), s2(3), s(3), area, nrm(3), u1(3), u2(3), p1, p2, z1, z2, ps, us
    given = 0.0_wp
    do k = box(1, 3), box(2, 3)
      do j = box(1, 2), box(2, 2)
        do i = box(1, 1), box(2, 1)
          if (.not. (f1%alpha(i, j, k) > 0.0_wp .and. f2%alpha(i, j, k) > 0.0_wp)) cycle
          if (.not. (q1(i, j, k, i_rho) > 0.0_wp .and. q2(i, j, k, i_rho) > 0.0_wp)) cycle
          s1 = surface(f1, i, j, k)
          s2 = surface(f2, i, j, k)
          s = 0.5_wp * (s1 - s2)
          area = norm2(s)
          if (.not. area > 0.0_wp) cycle
          nrm = s / area
          call side_state(eos1, shear1, q1(i, j, k, :), nrm, u1, p1, z1)
          call side_state(eos2, shear2, q2(i, j, k, :), nrm, u2, p2, z2)
          ps = (z2 * p1 + z1 * p2 + z1 * z2 * (dot_product(u1, nrm) - dot_product(u2, nrm))) &
            / (z1 + z2)
          if (.not. ps > 0.0_wp) cycle
          us = (z1 * dot_product(u1, nrm) + z2 * dot_product(u2, nrm) + p1 - p2) / (z1 + z2)
          do d = 1, 3
            r1(i, j, k, i_mx + d - 1) = r1(i, j, k, i_mx + d - 1) - ps * s(d)
            r2(i, j, k, i_mx + d - 1) = r2(i, j, k, i_mx + d - 1) + ps * s(d)
          end do
          r1(i, j, k, i_en) = r1(i, j, k, i_en) - ps * us * area
          r2(i, j, k, i_en) = r2(i, j, k, i_en) + ps * us * area
          given = given + ps * us * area * cell_volume(lay, offset, i)
          cells = cells + 1
        end do
      end do
    end do

  contains

    !> The interface of a phase in cell (i, j, k), per unit of the cell's volume, outward
    !> from the phase (what its wet faces leave open).
    function surface(f, i, j, k) result(sv)
      type(cut_faces_t), intent(in) :: f
      integer, intent(in) :: i, j, k
      real(wp) :: sv(3), rf, rc, wlo, whi
      sv = 0.0_wp
      wlo = 1.0_wp / lay%dx(1)
      whi = wlo
      if (lay%axisymmetric) then
        rf = lay%lo(1) + real(offset(1) + i - 1, wp) * lay%dx(1)
        rc = rf + 0.5_wp * lay%dx(1)
        wlo = rf / (rc * lay%dx(1))
        whi = (rf + lay%dx(1)) / (rc * lay%dx(1))
        sv(1) = f%plane(i, j, k) / rc
      end if
      sv(1) = sv(1) - (whi * f%ax(i, j, k) - wlo * f%ax(i - 1, j, k))
      if (lay%ndim >= 2) sv(2) = -(f%ay(i, j, k) - f%ay(i, j - 1, k)) / lay%dx(2)
      if (lay%ndim >= 3) sv(3) = -(f%az(i, j, k) - f%az(i, j, k - 1)) / lay%dx(3)
    end function surface

    !> A phase's velocity, normal stress P = p - n.S.n along nrm and impedance rho c (c
    !> the longitudinal speed with strength) from its cell state u (conserved variables).
    subroutine side_state(eos, shear, u, nrm, vel, pn, z)
      type(eos_t), intent(in) :: eos
      real(wp), intent(in) :: shear, u(:), nrm(3)
      real(wp), intent(out) :: vel(3), pn, z
      real(wp) :: rho(1), ux(1), uy(1), uz(1), p(1), e(1), c2(1), sn
      integer :: a, b
      call primitive_row(eos, 1, u(i_rho:i_rho), u(i_mx:i_mx), u(i_my:i_my), u(i_mz:i_mz), &
        u(i_en:i_en), rho, ux, uy, uz, p, e)
      call eos_sound_speed2(eos, 1, rho, p, c2)
      vel = [ux(1), uy(1), uz(1)]
      sn = 0.0_wp
      if (size(u) >= n_solid) then
        do a = 1, 3
          do b = 1, 3
            sn = sn + nrm(a) * u(stress_index(a, b)) / rho(1) * nrm(b)
          end do
        end do
      end if
      pn = p(1) - sn
      z = rho(1) * sqrt(max(c2(1), 0.0_wp) + 4.0_wp * shear / (3.0_wp * rho(1)))
    end subroutine side_state

  end subroutine cut_contact

end module m_gfm_cut_contact
