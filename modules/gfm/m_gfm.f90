!> The ghost-fluid method on one block (DESIGN sections 1 and 5, manual/interfaces.md): the
!> cells of the computed region (Phi < 0, m_levelset_bodies) are real; every cell of the
!> block interior with 0 < Phi <= width (3.5 cells: the reach of the ENO3 and WENO5
!> stencils of the real cells next to the surface) is a ghost, filled from the image point
!>   IP1 = x_P - 2 Phi n,  n = grad Phi / |grad Phi|  (out of the material)
!> (brought closer, but not nearer than the surface, where IP1's stencil would leave the
!> padded block)
!> by its boundary class: MVI at a free (void) surface, MRI at rigid body l. The value at IP1
!> comes from m_gfm_probe: 'trilinear', 'least_squares', or 'auto' (trilinear where its
!> stencil is complete, least squares elsewhere). Cells beyond the band hold a rest state
!> (rest density and pressure, at rest, no stress): they are never read by a real cell's
!> stencil and cost nothing to keep finite. The caller exchanges halos afterwards so that the
!> ghosts of neighbour blocks are seen too. Kernels only: no MPI, no I/O.
module m_gfm
  use m_kinds, only: wp, i8
  use m_layout, only: layout_t
  use m_eos, only: eos_t, eos_energy, eos_sound_speed2
  use m_euler, only: primitive_row
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_euler
  use m_levelset_bodies, only: ls_set_t, ls_region
  use m_gfm_probe, only: probe_trilinear, probe_least_squares
  use m_gfm_mvi, only: gfm_mvi
  use m_gfm_mri, only: gfm_mri
  implicit none
  private
  public :: gfm_work_t, gfm_work_init, gfm_fill, gfm_rest, gfm_counts_t
  public :: probe_kind_trilinear, probe_kind_least_squares, probe_kind_auto, probe_from_name

  integer, parameter :: probe_kind_trilinear = 1, probe_kind_least_squares = 2
  integer, parameter :: probe_kind_auto = 3

  !> What the fills of a run did (this rank): ghosts filled, by which probe, and how often
  !> a ghost needed help (too few real neighbours, a ghost pressure without sound speed).
  type :: gfm_counts_t
    integer(i8) :: ghosts = 0, trilinear = 0, least_squares = 0, mean = 0
    integer(i8) :: incomplete = 0   !< trilinear probes used with an incomplete stencil
    integer(i8) :: unfilled = 0     !< ghosts with no real cell near their image: rest state
    integer(i8) :: limited = 0      !< ghost pressure replaced by the image pressure
  end type gfm_counts_t

  type :: gfm_work_t
    real(wp), allocatable :: w(:, :, :, :)     !< primitive states (padded block, nflow)
    real(wp), allocatable :: bigphi(:, :, :)   !< composite level set Phi
    integer, allocatable :: owner(:, :, :)     !< 0 free surface, l rigid body l
    logical, allocatable :: isreal(:, :, :)
    real(wp), allocatable :: row(:)
  end type gfm_work_t

contains

  integer function probe_from_name(name) result(k)
    character(len=*), intent(in) :: name
    select case (trim(name))
    case ('trilinear')
      k = probe_kind_trilinear
    case ('least_squares')
      k = probe_kind_least_squares
    case default
      k = probe_kind_auto
    end select
  end function probe_from_name

  subroutine gfm_work_init(lay, nflow, work)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: nflow
    type(gfm_work_t), intent(out) :: work
    integer :: lo(3), hi(3)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    allocate(work%w(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nflow))
    allocate(work%bigphi(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
    allocate(work%owner(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
    allocate(work%isreal(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
    allocate(work%row(lo(1):hi(1)))
  end subroutine gfm_work_init

  !> Fill the ghost band of the block interior and put the rest state beyond it. q holds the
  !> nflow flow variables followed by the level sets; its halo must be current.
  subroutine gfm_fill(lay, eos, set, nflow, probe, band, rest, q, work, counts, dormant)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: nflow, probe
    real(wp), intent(in) :: band         !< ghost band width (m): 3.5 cells
    real(wp), intent(in) :: rest(2)      !< rest density and pressure
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    type(gfm_counts_t), intent(inout) :: counts
    logical, intent(out) :: dormant   !< every cell, halo included, lies beyond the band
    integer :: lo(3), hi(3), i, j, k, m, nr, npts, d, nd, k3(3)
    real(wp) :: qrest(nflow)
    real(wp) :: grad(3), s(3), wi(nflow), wg(nflow), c2(1), phi_p, dist
    logical :: complete
    nd = lay%ndim
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    nr = hi(1) - lo(1) + 1
    call ls_region(set, lo, hi, q(:, :, :, nflow+1:nflow+set%n), work%bigphi, work%owner)
    work%isreal = work%bigphi < 0.0_wp
    dormant = all(work%bigphi > band)
    ! a block with no cell outside the computed region has nothing to fill
    if (all(work%isreal(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3)))) return
    qrest = rest_state(eos, nflow, rest)
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        call primitive_row(eos, nr, q(:, j, k, i_rho), q(:, j, k, i_mx), q(:, j, k, i_my), &
          q(:, j, k, i_mz), q(:, j, k, i_en), work%w(:, j, k, 1), work%w(:, j, k, 2), &
          work%w(:, j, k, 3), work%w(:, j, k, 4), work%w(:, j, k, 5), work%row)
        do m = n_euler + 1, nflow
          work%w(:, j, k, m) = q(:, j, k, m) / q(:, j, k, i_rho)
        end do
      end do
    end do
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          phi_p = work%bigphi(i, j, k)
          if (phi_p < 0.0_wp) cycle
          if (phi_p > band) then
            q(i, j, k, 1:nflow) = qrest
            cycle
          end if
          counts%ghosts = counts%ghosts + 1
          k3 = [i, j, k]
          grad = 0.0_wp
          do d = 1, nd
            grad(d) = central(d)
          end do
          if (.not. norm2(grad) > 0.0_wp) grad(1) = 1.0_wp
          grad = grad / norm2(grad)
          ! IP1 at 2 Phi along -n, brought closer where its stencil would leave the padded
          ! block (a ghost near the block's edge): never below Phi, the surface itself
          dist = 2.0_wp * phi_p
          do d = 1, nd
            if (grad(d) > 0.0_wp) dist = min(dist, real(k3(d) - lo(d) - 1, wp) * lay%dx(d) &
              / grad(d))
            if (grad(d) < 0.0_wp) dist = min(dist, real(k3(d) - hi(d) + 1, wp) * lay%dx(d) &
              / grad(d))
          end do
          dist = max(dist, phi_p)
          s = real([i, j, k], wp)
          s(1:nd) = s(1:nd) - dist * grad(1:nd) / lay%dx(1:nd)
          complete = .false.
          if (probe /= probe_kind_least_squares) then
            call probe_trilinear(nd, lo, hi, work%w, work%isreal, s, wi, complete)
            if (complete .or. probe == probe_kind_trilinear) then
              counts%trilinear = counts%trilinear + 1
              if (.not. complete) counts%incomplete = counts%incomplete + 1
            end if
          end if
          if (.not. complete .and. probe /= probe_kind_trilinear) then
            call probe_least_squares(nd, lo, hi, work%w, work%isreal, s, wi, npts)
            if (npts > 0) counts%least_squares = counts%least_squares + 1
            if (npts < 0) counts%mean = counts%mean + 1
            if (npts == 0) then
              counts%unfilled = counts%unfilled + 1
              q(i, j, k, 1:nflow) = qrest
              cycle
            end if
          end if
          if (work%owner(i, j, k) == 0) then
            call gfm_mvi(nd, grad, wi, wg)
          else
            call gfm_mri(nd, grad, set%velocity(:, work%owner(i, j, k)), wi, wg)
          end if
          call eos_sound_speed2(eos, 1, wg(1:1), wg(5:5), c2)
          if (.not. (wg(1) > 0.0_wp .and. c2(1) > 0.0_wp)) then
            counts%limited = counts%limited + 1
            wg(1) = max(wg(1), wi(1), rest(1) * 1.0e-6_wp)
            wg(5) = wi(5)
            call eos_sound_speed2(eos, 1, wg(1:1), wg(5:5), c2)
            if (.not. c2(1) > 0.0_wp) wg(1:5) = [rest(1), wg(2:4), rest(2)]
          end if
          call put_state(eos, wg, q(i, j, k, 1:nflow))
        end do
      end do
    end do

  contains

    !> d Phi / dx_d at (i, j, k) by central differences (one-sided at the array's edge)
    real(wp) function central(dd) result(g)
      integer, intent(in) :: dd
      integer :: a(3), b(3)
      a = [i, j, k]
      b = a
      a(dd) = min(a(dd) + 1, hi(dd))
      b(dd) = max(b(dd) - 1, lo(dd))
      g = (work%bigphi(a(1), a(2), a(3)) - work%bigphi(b(1), b(2), b(3))) &
        / (real(a(dd) - b(dd), wp) * lay%dx(dd))
    end function central

  end subroutine gfm_fill

  !> After a stage update: every interior cell outside the computed region goes to the rest
  !> state, so that no stale ghost value is taken for a state (the time step, the
  !> admissibility test and the totals read real cells and rest states only).
  subroutine gfm_rest(lay, eos, set, nflow, rest, q, work)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: nflow
    real(wp), intent(in) :: rest(2)
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    integer :: lo(3), hi(3), i, j, k
    real(wp) :: qrest(nflow)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    call ls_region(set, lo, hi, q(:, :, :, nflow+1:nflow+set%n), work%bigphi, work%owner)
    if (all(work%bigphi(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3)) < 0.0_wp)) return
    qrest = rest_state(eos, nflow, rest)
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          if (work%bigphi(i, j, k) < 0.0_wp) cycle
          q(i, j, k, 1:nflow) = qrest
        end do
      end do
    end do
  end subroutine gfm_rest

  !> Conserved variables of the rest state (density rest(1), pressure rest(2), at rest, no
  !> stress), computed once per block rather than once per cell.
  function rest_state(eos, nflow, rest) result(qr)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: nflow
    real(wp), intent(in) :: rest(2)
    real(wp) :: qr(nflow)
    integer :: m
    call put_state(eos, [rest(1), 0.0_wp, 0.0_wp, 0.0_wp, rest(2), &
      (0.0_wp, m = n_euler + 1, nflow)], qr)
  end function rest_state

  !> Conserved variables of one cell from a primitive state.
  subroutine put_state(eos, w, qc)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: w(:)
    real(wp), intent(out) :: qc(:)
    real(wp) :: e(1)
    call eos_energy(eos, 1, w(1:1), w(5:5), e)
    qc(i_rho) = w(1)
    qc(i_mx:i_mz) = w(1) * w(2:4)
    qc(i_en) = w(1) * (e(1) + 0.5_wp * sum(w(2:4)**2))
    if (size(qc) > n_euler) qc(n_euler+1:) = w(1) * w(n_euler+1:)
  end subroutine put_state

end module m_gfm
