!> The level-set bodies of a scene and the regions they leave to each phase (DESIGN sections
!> 1 and 5, manual/interfaces.md). Each body of a material other than the base material, each
!> void body and each rigid body carries a level set phi_l (negative inside). Every material
!> body is a phase with a flow state of its own, and so is the base material when it is not
!> void (phase 1). The region of phase p is where its material is, outside every void and
!> rigid body; its composite level set
!>   Phi_p = max( own_p, max_l -phi_l over void and rigid bodies ),
!>   own_p = phi_l for the phase of material body l,
!>         = max_l -phi_l over the material bodies for the base phase (or -huge),
!> is negative in its real cells. The term that attains the maximum says which boundary a
!> ghost cell (Phi_p > 0) belongs to: owner 0 a void body (free surface), l > 0 rigid body l,
!> -l the surface of material body l (the phase's own surface, or for the base phase the body
!> it borders): a material-material interface or, with no partner near, a free surface.
!> Kernels only: no MPI, no I/O.
module m_levelset_bodies
  use m_kinds, only: wp, name_len
  implicit none
  private
  public :: ls_material, ls_void, ls_rigid, ls_set_t, ls_region, ls_separate

  integer, parameter :: ls_material = 1, ls_void = 2, ls_rigid = 3

  type :: ls_set_t
    integer :: n = 0                        !< level sets
    logical :: base_flows = .true.          !< the base material is a phase (phase 1)
    integer :: nphase = 1                   !< phases: flow states per cell
    integer, allocatable :: kind(:)         !< ls_material | ls_void | ls_rigid
    integer, allocatable :: body(:)         !< index of the body in the deck
    integer, allocatable :: phase(:)        !< phase of a material body's level set, else 0
    integer, allocatable :: colour(:)       !< the colour of a body of grains, else 0
    character(len=name_len), allocatable :: name(:)
    real(wp), allocatable :: velocity(:, :) !< (3, n): velocity of a rigid body
    !> where two material bodies of different phases overlap, each phase's region ends at
    !> their mid-surface (ls_region; set by the cut-cell update with contacts)
    logical :: mid_contacts = .false.
  end type ls_set_t

contains

  !> Composite level set bigphi and boundary owner of phase p over the cells of a padded
  !> block; phi holds the n level sets on the same shape.
  subroutine ls_region(set, p, lo, hi, phi, bigphi, owner)
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: p, lo(3), hi(3)
    real(wp), intent(in) :: phi(lo(1):, lo(2):, lo(3):, :)
    real(wp), intent(out) :: bigphi(lo(1):, lo(2):, lo(3):)
    integer, intent(out) :: owner(lo(1):, lo(2):, lo(3):)
    integer :: l, i, j, k
    logical :: base
    ! level set by level set over the whole box (the inner loops vectorise, as blends); the
    ! first that attains the extremum owns the cell, as a cell-by-cell loop over l would have
    ! it. Explicit loops, not where blocks: a where block of two assignments builds its mask
    ! in a temporary array first.
    base = set%base_flows .and. p == 1
    bigphi(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)) = merge(-huge(1.0_wp), huge(1.0_wp), base)
    owner(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)) = 0
    do l = 1, set%n
      if (set%kind(l) /= ls_material) cycle
      if (base) then
        call take_max(l, -l)
      else if (set%phase(l) == p) then
        do k = lo(3), hi(3)
          do j = lo(2), hi(2)
            do i = lo(1), hi(1)
              if (phi(i, j, k, l) < bigphi(i, j, k)) then
                bigphi(i, j, k) = phi(i, j, k, l)
                owner(i, j, k) = -l
              end if
            end do
          end do
        end do
      end if
    end do
    if (set%mid_contacts .and. .not. base) call mid_surfaces()
    do l = 1, set%n
      if (set%kind(l) == ls_material) cycle
      call take_max(l, merge(l, 0, set%kind(l) == ls_rigid))
    end do

  contains

    !> where the phase's own level set (bigphi so far) and a material body of another phase
    !> overlap, the phase ends at their mid-surface, (own - phi_m) / 2, which that body
    !> owns: the region ls_separate would leave them, taken at every stage, so that two
    !> phases in a cell meet at one surface (the contact's geometry, m_gfm_cut_contact).
    !> Where they do not overlap (own + phi_m >= 0) this is not above own: no change.
    subroutine mid_surfaces()
      real(wp) :: own, mid
      integer :: m
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          do i = lo(1), hi(1)
            own = bigphi(i, j, k)
            do m = 1, set%n
              if (set%kind(m) /= ls_material .or. set%phase(m) == p) cycle
              mid = 0.5_wp * (own - phi(i, j, k, m))
              if (mid > bigphi(i, j, k)) then
                bigphi(i, j, k) = mid
                owner(i, j, k) = -m
              end if
            end do
          end do
        end do
      end do
    end subroutine mid_surfaces

    !> where -phi_l exceeds bigphi, bigphi = -phi_l and the owner o
    subroutine take_max(l, o)
      integer, intent(in) :: l, o
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          do i = lo(1), hi(1)
            if (-phi(i, j, k, l) > bigphi(i, j, k)) then
              bigphi(i, j, k) = -phi(i, j, k, l)
              owner(i, j, k) = o
            end if
          end do
        end do
      end do
    end subroutine take_max
  end subroutine ls_region

  !> Bodies may not overlap: where two material level sets are both negative, both move to
  !> their mid-surface, phi_l <- phi_l - (phi_a + phi_b) / 2 for the two smallest phi_a,
  !> phi_b (Losasso et al. 2006), which leaves phi_a = -phi_b: one shared surface. phi holds
  !> the n level sets of the cells of one array.
  pure subroutine ls_separate(set, phi)
    type(ls_set_t), intent(in) :: set
    real(wp), intent(inout) :: phi(:, :, :, :)
    integer :: i, j, k, l
    real(wp) :: a, b, shift
    do k = 1, size(phi, 3)
      do j = 1, size(phi, 2)
        do i = 1, size(phi, 1)
          a = huge(1.0_wp)
          b = huge(1.0_wp)
          do l = 1, set%n
            if (set%kind(l) /= ls_material) cycle
            if (phi(i, j, k, l) < a) then
              b = a
              a = phi(i, j, k, l)
            else if (phi(i, j, k, l) < b) then
              b = phi(i, j, k, l)
            end if
          end do
          if (.not. a + b < 0.0_wp .or. .not. b < 0.0_wp) cycle
          shift = 0.5_wp * (a + b)
          do l = 1, set%n
            if (set%kind(l) == ls_material) phi(i, j, k, l) = phi(i, j, k, l) - shift
          end do
        end do
      end do
    end do
  end subroutine ls_separate

end module m_levelset_bodies
