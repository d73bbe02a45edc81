!> The level-set bodies of a scene and the region they leave to the flow (DESIGN sections 1
!> and 5, manual/interfaces.md). Each body of a material other than the base material, each
!> void body and each rigid body carries a level set phi_l (negative inside). The computed
!> region is where the flowing material is: inside some material body (or anywhere, when the
!> base is that material), outside every void and rigid body. Its composite level set
!>   Phi = max( min_l phi_l over material bodies (or -huge), max_l -phi_l over void and rigid )
!> is negative in real cells; the term that attains the maximum says which boundary a ghost
!> cell (Phi > 0) belongs to: 0 for a free (void) surface, l for rigid body l.
!> Kernels only: no MPI, no I/O.
module m_levelset_bodies
  use m_kinds, only: wp, name_len
  implicit none
  private
  public :: ls_material, ls_void, ls_rigid, ls_set_t, ls_region

  integer, parameter :: ls_material = 1, ls_void = 2, ls_rigid = 3

  type :: ls_set_t
    integer :: n = 0                        !< level sets
    logical :: base_flows = .true.          !< the base material is the flowing one
    integer, allocatable :: kind(:)         !< ls_material | ls_void | ls_rigid
    integer, allocatable :: body(:)         !< index of the body in the deck
    character(len=name_len), allocatable :: name(:)
    real(wp), allocatable :: velocity(:, :) !< (3, n): velocity of a rigid body
  end type ls_set_t

contains

  !> Composite level set bigphi and boundary owner (0 void/free, l rigid body l) of the cells
  !> of a padded block; phi holds the n level sets on the same shape.
  subroutine ls_region(set, lo, hi, phi, bigphi, owner)
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: lo(3), hi(3)
    real(wp), intent(in) :: phi(lo(1):, lo(2):, lo(3):, :)
    real(wp), intent(out) :: bigphi(lo(1):, lo(2):, lo(3):)
    integer, intent(out) :: owner(lo(1):, lo(2):, lo(3):)
    integer :: i, j, k, l
    real(wp) :: v, t
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        do i = lo(1), hi(1)
          v = merge(-huge(1.0_wp), huge(1.0_wp), set%base_flows)
          do l = 1, set%n
            if (set%kind(l) == ls_material .and. .not. set%base_flows) &
              v = min(v, phi(i, j, k, l))
          end do
          owner(i, j, k) = 0
          do l = 1, set%n
            if (set%kind(l) == ls_material) cycle
            t = -phi(i, j, k, l)
            if (t > v) then
              v = t
              owner(i, j, k) = merge(l, 0, set%kind(l) == ls_rigid)
            end if
          end do
          bigphi(i, j, k) = v
        end do
      end do
    end do
  end subroutine ls_region

end module m_levelset_bodies
