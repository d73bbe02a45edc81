!> The geometry of the cut-cell phase on one block at one stage (issue 15, manual/theory.md
!> section 7, manual/interfaces.md section 2c): from the phase's composite level set over
!> the padded block, the interior faces' apertures and the fractions (m_levelset_cut), the
!> fractions also into the halo less its outer layer (for the mixing of m_gfm_cut). The
!> level set moves at every stage (it is advanced with the state), so the geometry is made
!> at every stage; its scratch is kept from block to block and stage to stage (m_gfm_cut_work).
!> Only the box of the cells within one cell of the phase is cut: a cell no corner of which
!> lies in it has fraction and apertures 0 (m_levelset_cut), which the arrays hold beyond.
!> What the stage does with the geometry is m_gfm_cut's.
module m_gfm_cut_geometry
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_euler, only: cut_faces_t
  use m_levelset_cut, only: levelset_cut
  use m_gfm_cut_cells, only: full
  use m_gfm_cut_work, only: cut_work_t, fit_work
  use m_gfm_cut_box, only: box_below, box_union, box_empty
  implicit none
  private
  public :: cut_block_geometry, wet_reach_box

  !> the level set (in cells) below which a cell is one the surface may wet before the next
  !> stage: it moves less than a cell in a stage, a wet cell is within a cell of one below
  !> zero, and a level set is only nearly a distance: 3
  real(wp), parameter :: wet_reach = 3.0_wp

contains

  !> The cells of the padded block (in its cells' indices, the box cut_block_geometry's box
  !> will have by the next stage at most) that the surface may wet before the next stage:
  !> every cell whose level set bigphi (over the padded block) is below wet_reach cells, in
  !> axisymmetry at every r as the geometry's box. A new part of the region appears where the
  !> level set was small, however far from the wet cells: the 400 m/s bar's foot entering a
  !> block along the floor wet a whole row at once (m_gfm_cut's near cells, interfaces.md 2c).
  function wet_reach_box(lay, n, bigphi) result(box)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: n(3)
    real(wp), intent(in) :: bigphi(:, :, :)
    integer :: box(2, 3)
    box = box_below(bigphi, wet_reach * maxval(lay%dx(1:lay%ndim)))
    if (any(box(1, :) > box(2, :))) return
    box(1, :) = box(1, :) - lay%ng
    box(2, :) = box(2, :) - lay%ng
    if (lay%axisymmetric) box(:, 1) = [1 - lay%ng(1), n(1) + lay%ng(1)]
  end function wet_reach_box

  !> The geometry of a block with n interior cells at offset in the grid lay, from the
  !> phase's level set bigphi over the padded block: the interior faces' apertures,
  !> fractions, planar fractions and partly filled cells into f, the fractions alpha_e over
  !> the padded block less its outer layer. Beyond an outflow side (open_side) the level
  !> set continues linearly (the halo holds a copy of the edge cell), so that the side's
  !> faces get the apertures the surface really has there. box: the cells (of the padded
  !> block less its outer layer) beyond which every fraction is 0.
  subroutine cut_block_geometry(work, lay, offset, n, bigphi, open_side, f, alpha_e, box)
    type(cut_work_t), intent(inout) :: work
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: offset(3), n(3)
    real(wp), intent(in) :: bigphi(:, :, :)
    logical, intent(in) :: open_side(2, 3)
    type(cut_faces_t), intent(inout) :: f
    real(wp), allocatable, intent(inout) :: alpha_e(:, :, :)
    integer, intent(out) :: box(2, 3)
    integer :: e(3), ne(3), g1(3), d, l, c, fresh(2, 3), cb(2, 3)
    logical :: extended, refit
    real(wp) :: r0
    e = max(lay%ng - 1, 0)
    ne = n + 2 * e
    g1 = merge(1, 0, lay%ng > 0)
    refit = .true.
    if (allocated(work%ax)) refit = any(lbound(work%ax) /= [-e(1), 1 - e(2), 1 - e(3)]) &
      .or. any(ubound(work%ax) /= n + e)
    call fit_work(alpha_e, 1 - e, n + e)
    call fit_work(work%plane, 1 - e, n + e)
    call fit_work(work%ax, [-e(1), 1 - e(2), 1 - e(3)], n + e)
    call fit_work(work%ay, [1 - e(1), -e(2), 1 - e(3)], n + e)
    call fit_work(work%az, [1 - e(1), 1 - e(2), -e(3)], n + e)
    r0 = lay%lo(1) + real(offset(1) - e(1), wp) * lay%dx(1)
    extended = .false.
    do d = 1, lay%ndim
      if (open_side(1, d) .and. offset(d) == 0) extended = .true.
      if (open_side(2, d) .and. offset(d) + n(d) == lay%cells(d)) extended = .true.
    end do
    ! the scratch is zero beyond the last block's box (everywhere when just fitted)
    if (refit) then
      work%ax = 0.0_wp
      work%ay = 0.0_wp
      work%az = 0.0_wp
      work%plane = 0.0_wp
    else
      call zero_box(work%box)
    end if
    alpha_e = 0.0_wp
    if (extended) then
      call fit_work(work%phi, [1, 1, 1], shape(bigphi))
      work%phi = bigphi
      do d = 1, lay%ndim
        if (open_side(1, d) .and. offset(d) == 0) then
          c = lay%ng(d) + 1
          do l = 1, lay%ng(d)
            call extend(d, c - l, c, c + 1, real(l, wp))
          end do
        end if
        if (open_side(2, d) .and. offset(d) + n(d) == lay%cells(d)) then
          c = lay%ng(d) + n(d)
          do l = 1, lay%ng(d)
            call extend(d, c + l, c, c - 1, real(l, wp))
          end do
        end if
      end do
      call cut_box(work%phi)
    else
      call cut_box(bigphi)
    end if
    work%box = box
    ! into f: the box of the cells it may have had nonzero until now and of those it may
    ! have now (with their faces); beyond both it holds zeros already (the scratch is zero
    ! beyond work%box)
    fresh(1, :) = max(box(1, :), 1 - g1)
    fresh(2, :) = min(box(2, :), n + g1)
    if (any(fresh(1, :) > fresh(2, :))) fresh = box_empty
    cb = box_union(f%box, fresh)
    cb(1, :) = max(cb(1, :), 1 - g1)
    cb(2, :) = min(cb(2, :), n + g1)
    if (all(cb(1, :) <= cb(2, :))) then
      f%partial(cb(1, 1):cb(2, 1), cb(1, 2):cb(2, 2), cb(1, 3):cb(2, 3)) = &
        alpha_e(cb(1, 1):cb(2, 1), cb(1, 2):cb(2, 2), cb(1, 3):cb(2, 3)) > 0.0_wp .and. &
        alpha_e(cb(1, 1):cb(2, 1), cb(1, 2):cb(2, 2), cb(1, 3):cb(2, 3)) < full
      cb(1, :) = max(cb(1, :), 1)
      cb(2, :) = min(cb(2, :), n)
    end if
    if (all(cb(1, :) <= cb(2, :))) then
      associate (x => cb(:, 1), y => cb(:, 2), z => cb(:, 3))
        f%ax(x(1)-1:x(2), y(1):y(2), z(1):z(2)) = work%ax(x(1)-1:x(2), y(1):y(2), z(1):z(2))
        f%ay(x(1):x(2), y(1)-1:y(2), z(1):z(2)) = work%ay(x(1):x(2), y(1)-1:y(2), z(1):z(2))
        f%az(x(1):x(2), y(1):y(2), z(1)-1:z(2)) = work%az(x(1):x(2), y(1):y(2), z(1)-1:z(2))
        f%alpha(x(1):x(2), y(1):y(2), z(1):z(2)) = alpha_e(x(1):x(2), y(1):y(2), z(1):z(2))
        f%plane(x(1):x(2), y(1):y(2), z(1):z(2)) = work%plane(x(1):x(2), y(1):y(2), z(1):z(2))
      end associate
    end if
    f%box = fresh

  contains

    !> the geometry of the box of the cells within one cell (3^ndim) of one whose level set
    !> phi (over the padded block) is < 0; in axisymmetry every r (r0 is the block's)
    subroutine cut_box(phi)
      real(wp), intent(in) :: phi(:, :, :)
      integer :: below(2, 3)
      ! (phi's index is the padded cell's + e + g1)
      below = box_below(phi)
      box(1, :) = max(below(1, :) - e - 2 * g1, 1 - e)
      box(2, :) = min(below(2, :) - e, n + e)
      if (any(box(1, :) > box(2, :))) return
      if (lay%axisymmetric) box(:, 1) = [1 - e(1), n(1) + e(1)]
      associate (b1 => box(1, :), b2 => box(2, :))
        call cut_part(b2 - b1 + 1, phi(b1(1)+e(1):b2(1)+e(1)+2*g1(1), &
          b1(2)+e(2):b2(2)+e(2)+2*g1(2), b1(3)+e(3):b2(3)+e(3)+2*g1(3)))
      end associate
    end subroutine cut_box

    !> the geometry of the box's m cells from its level set ph (with one cell around where
    !> active), into the scratch and alpha_e (contiguous copies for m_levelset_cut's kernels)
    subroutine cut_part(m, ph)
      integer, intent(in) :: m(3)
      real(wp), intent(in) :: ph(:, :, :)
      real(wp) :: p(1-g1(1):m(1)+g1(1), 1-g1(2):m(2)+g1(2), 1-g1(3):m(3)+g1(3))
      real(wp) :: sx(0:m(1), m(2), m(3)), sy(m(1), 0:m(2), m(3)), sz(m(1), m(2), 0:m(3))
      real(wp) :: sa(m(1), m(2), m(3)), sp(m(1), m(2), m(3))
      p = ph
      call levelset_cut(lay%ndim, lay%axisymmetric, m, g1, lay%dx, r0, p, sx, sy, sz, sa, &
        alpha_plane=sp)
      associate (b1 => box(1, :), b2 => box(2, :))
        work%ax(b1(1)-1:b2(1), b1(2):b2(2), b1(3):b2(3)) = sx
        work%ay(b1(1):b2(1), b1(2)-1:b2(2), b1(3):b2(3)) = sy
        work%az(b1(1):b2(1), b1(2):b2(2), b1(3)-1:b2(3)) = sz
        alpha_e(b1(1):b2(1), b1(2):b2(2), b1(3):b2(3)) = sa
        work%plane(b1(1):b2(1), b1(2):b2(2), b1(3):b2(3)) = sp
      end associate
    end subroutine cut_part

    !> the scratch's apertures and planar fractions of box bx (and its low faces) to zero
    subroutine zero_box(bx)
      integer, intent(in) :: bx(2, 3)
      if (any(bx(1, :) > bx(2, :))) return
      work%ax(bx(1, 1)-1:bx(2, 1), bx(1, 2):bx(2, 2), bx(1, 3):bx(2, 3)) = 0.0_wp
      work%ay(bx(1, 1):bx(2, 1), bx(1, 2)-1:bx(2, 2), bx(1, 3):bx(2, 3)) = 0.0_wp
      work%az(bx(1, 1):bx(2, 1), bx(1, 2):bx(2, 2), bx(1, 3)-1:bx(2, 3)) = 0.0_wp
      work%plane(bx(1, 1):bx(2, 1), bx(1, 2):bx(2, 2), bx(1, 3):bx(2, 3)) = 0.0_wp
    end subroutine zero_box

    !> layer `to` (an index of phi along dd) = edge + l (edge - inner), the whole layer
    subroutine extend(dd, to, edge, inner, l)
      integer, intent(in) :: dd, to, edge, inner
      real(wp), intent(in) :: l
      associate (phi => work%phi)
        select case (dd)
        case (1)
          phi(to, :, :) = phi(edge, :, :) + l * (phi(edge, :, :) - phi(inner, :, :))
        case (2)
          phi(:, to, :) = phi(:, edge, :) + l * (phi(:, edge, :) - phi(:, inner, :))
        case default
          phi(:, :, to) = phi(:, :, edge) + l * (phi(:, :, edge) - phi(:, :, inner))
        end select
      end associate
    end subroutine extend
  end subroutine cut_block_geometry

end module m_gfm_cut_geometry
