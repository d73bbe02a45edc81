!> The ghost-fluid method on one block (DESIGN sections 1 and 5, manual/interfaces.md). Each
!> phase (the base material, each material body) has a state of its own; the cells of its
!> region (Phi_p < 0, m_levelset_bodies) are real; every cell of the
!> block interior with 0 < Phi_p <= width (3.5 cells: the reach of the ENO3 and WENO5
!> stencils of the real cells next to the surface) is a ghost, filled from the image point
!>   IP1 = x_P - 2 Phi n,  n = grad Phi / |grad Phi|  (out of the material)
!> (brought closer, but not nearer than the surface, where IP1's stencil would leave the
!> padded block)
!> by its boundary class: MVI at a free (void) surface, MRI at rigid body l, MMI where the
!> other side is another phase (the base material, or a body within kappa dx: a collision;
!> the partner's state is read at the ghost cell itself). The value at IP1
!> comes from m_gfm_probe: 'trilinear', 'least_squares', or 'auto' (trilinear where its
!> stencil is complete, least squares elsewhere; at a contact kept within its real cells'
!> range). Cells beyond the band hold a rest state (rest density and pressure, at rest, no
!> stress): they are never read by a real cell's stencil and cost nothing to keep finite.
!> The caller exchanges halos afterwards so that the ghosts of neighbour blocks are seen
!> too. Kernels only: no MPI, no I/O.
module m_gfm
  use m_kinds, only: wp, i8
  use m_text, only: choice_index
  use m_layout, only: layout_t, cell_volume
  use m_eos, only: eos_t, eos_energy, eos_sound_speed2, eos_pressure, eos_ideal_gas
  use m_elastoplastic, only: primitive_row
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en, n_euler, i_epsp
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_material
  use m_levelset_geometry, only: levelset_gradient_at
  use m_gfm_probe, only: probe_trilinear, probe_least_squares, probe_scalar, deepest_on_ray
  use m_gfm_mvi, only: gfm_mvi
  use m_gfm_mri, only: gfm_mri
  use m_gfm_mmi, only: gfm_mmi
  implicit none
  private
  public :: gfm_work_t, gfm_work_init, gfm_fill, gfm_rest, gfm_counts_t, gfm_scene_t
  public :: gfm_drop_debris, gfm_dormant, gf_t, gf_fit
  public :: probe_kind_trilinear, probe_kind_least_squares, probe_kind_auto, probe_from_name
  public :: probe_names, gfm_count_names, gfm_count_list

  integer, parameter :: probe_kind_trilinear = 1, probe_kind_least_squares = 2
  integer, parameter :: probe_kind_auto = 3
  !> the deck's names (&numerics gfm_probe): name k stands for probe kind k
  character(len=13), parameter :: probe_names(3) = [character(len=13) :: 'trilinear', &
    'least_squares', 'auto']

  !> What the fills of a run did (this rank): ghosts filled, by which probe, and how often
  !> a ghost needed help (too few real neighbours, a ghost pressure without sound speed).
  type :: gfm_counts_t
    integer(i8) :: ghosts = 0, trilinear = 0, least_squares = 0, mean = 0
    integer(i8) :: incomplete = 0   !< trilinear probes used with an incomplete stencil
    integer(i8) :: unfilled = 0     !< ghosts with no real cell near their image: rest state
    integer(i8) :: limited = 0      !< ghost pressure replaced by the image pressure
    integer(i8) :: mmi = 0          !< ghosts filled across a material-material interface
    integer(i8) :: separated = 0    !< colliding ghosts with tension: treated as free
    integer(i8) :: debris = 0       !< inadmissible surface cells taken out of a body
    integer(i8) :: absent = 0       !< phase right-hand sides skipped: the phase not in the block
  end type gfm_counts_t
  !> the counts as one list (gfm_count_list), in this order, with their names in run.json
  !> (m_run_report; run.log says them in the same order, m_run_log)
  character(len=22), parameter :: gfm_count_names(11) = [character(len=22) :: 'ghost_fills', &
    'trilinear', 'incomplete_stencil', 'least_squares', 'mean_of_neighbours', &
    'without_real_neighbour', 'pressures_limited', 'mmi', 'contact_in_tension', 'debris', &
    'absent_phase_rhs']

  type :: gfm_work_t
    real(wp), allocatable :: w(:, :, :, :, :)  !< primitive states (padded block, nflow, phase)
    real(wp), allocatable :: bigphi(:, :, :, :) !< composite level set Phi_p of each phase
    integer, allocatable :: owner(:, :, :, :)  !< boundary owner (m_levelset_bodies)
    logical, allocatable :: isreal(:, :, :, :)
    real(wp), allocatable :: row(:)
  end type gfm_work_t

  !> What the fill of one block needs to know of the phases and the scene.
  type :: gfm_scene_t
    type(eos_t), allocatable :: eos(:)     !< equation of state of each phase
    real(wp), allocatable :: shear(:)      !< shear modulus of each phase (0: no strength)
    real(wp), allocatable :: rest(:, :)    !< (2, phase): rest density and pressure
    integer :: nflow = n_euler, probe = probe_kind_auto
    real(wp) :: band = 0.0_wp              !< ghost band width (m): 3.5 cells
    real(wp) :: contact = 0.0_wp           !< kappa dx: largest gap of a collision (m)
  end type gfm_scene_t

  !> The ghost-fluid state of a run: what the fills need of the phases and the scene, the
  !> work space of one block, what the fills did, which blocks are dormant (every cell, halo
  !> included, beyond every band: not computed), and the work space of the level sets' rates
  !> (m_levelset_motion).
  type :: gf_t
    type(gfm_scene_t) :: scn
    type(gfm_work_t) :: work
    type(gfm_counts_t) :: counts
    logical, allocatable :: dormant(:)
    real(wp), allocatable :: vel(:, :, :, :)   !< level-set advection velocity (padded block)
    real(wp), allocatable :: ls_rhs(:, :, :)
    !> the phases absent from the block being staged (phase_rhs: every cell more than two
    !> cells beyond the phase's region), whose update and corrections the stage skips
    logical, allocatable :: absent(:)
    !> rested(b): block b's interior holds each phase's rest state in every cell that lay
    !> outside the phase's region when it was last written (by gfm_rest after a stage, or by
    !> gfm_fill on a dormant block) and nothing has written since but a region's own cells;
    !> false after the start, a restart, a rebalance and a step redone (m_gfm_stage, m_step)
    logical, allocatable :: rested(:)
  end type gf_t

contains

  !> The counts of c in the order of gfm_count_names.
  pure function gfm_count_list(c) result(v)
    type(gfm_counts_t), intent(in) :: c
    integer(i8) :: v(size(gfm_count_names))
    v = [c%ghosts, c%trilinear, c%incomplete, c%least_squares, c%mean, c%unfilled, &
      c%limited, c%mmi, c%separated, c%debris, c%absent]
  end function gfm_count_list

  !> Shape gf's work space for a block of layout (or view) bl, when it has another extent
  !> than the block it was last shaped for (the last block along a direction may differ).
  subroutine gf_fit(gf, bl, nflow, nphase)
    type(gf_t), intent(inout) :: gf
    type(layout_t), intent(in) :: bl
    integer, intent(in) :: nflow, nphase
    integer :: lo(3), hi(3), n(3)
    n = bl%bsize
    if (allocated(gf%ls_rhs)) then
      if (all(shape(gf%ls_rhs) == n)) return
      deallocate(gf%vel, gf%ls_rhs)
    end if
    lo = 1 - bl%ng
    hi = n + bl%ng
    call gfm_work_init(bl, nflow, nphase, gf%work)
    allocate(gf%vel(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), 3), gf%ls_rhs(n(1), n(2), n(3)))
  end subroutine gf_fit

  !> The probe kind of a deck name (one of probe_names).
  integer function probe_from_name(name) result(k)
    character(len=*), intent(in) :: name
    k = choice_index(probe_names, name, 'probe_from_name')
  end function probe_from_name

  subroutine gfm_work_init(lay, nflow, nphase, work)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: nflow, nphase
    type(gfm_work_t), intent(out) :: work
    integer :: lo(3), hi(3)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    allocate(work%w(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nflow, nphase))
    allocate(work%bigphi(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nphase))
    allocate(work%owner(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nphase))
    allocate(work%isreal(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), nphase))
    allocate(work%row(lo(1):hi(1)))
  end subroutine gfm_work_init

  !> Fill the ghost bands of every phase in the block interior and put each phase's rest
  !> state beyond its band. q holds the nflow flow variables of each phase in turn, then the
  !> level sets; its halo must be current. rested: the interior holds each phase's rest
  !> state outside its region as it was last written (gf_t's rested), so every cell beyond the
  !> band does already (the level sets have not moved a band since) and none is written again.
  subroutine gfm_fill(lay, scn, set, q, work, counts, dormant, rested)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    type(ls_set_t), intent(in) :: set
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    type(gfm_counts_t), intent(inout) :: counts
    logical, intent(out) :: dormant   !< every cell, halo included, lies beyond every band
    logical, intent(in) :: rested
    integer :: lo(3), hi(3), j, k, p, nflow, ils
    logical :: busy(set%nphase)
    nflow = scn%nflow
    ils = set%nphase * nflow
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    do p = 1, set%nphase
      call ls_region(set, p, lo, hi, q(:, :, :, ils+1:ils+set%n), work%bigphi(:, :, :, p), &
        work%owner(:, :, :, p))
      work%isreal(:, :, :, p) = work%bigphi(:, :, :, p) < 0.0_wp
      ! a phase with no cell of the interior outside its region has nothing to fill
      busy(p) = .not. all(work%isreal(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3), p))
    end do
    dormant = all(work%bigphi > scn%band)
    if (dormant) then
      if (rested) return
      ! every cell beyond every band: the rest states, whatever the halo holds (a dormant
      ! block's flow halo is not kept current, m_halo)
      do p = 1, set%nphase
        call put_rest(lay, scn, p, q)
      end do
      return
    end if
    if (.not. any(busy)) return
    do p = 1, set%nphase
      call primitives(p)
    end do
    do p = 1, set%nphase
      if (.not. busy(p)) cycle
      call fill_phase(lay, scn, set, p, q, work, counts, rested)
    end do

  contains

    !> Phase pp's primitives on the rows of the padded block that come within reach of its
    !> region: a probe reads the real cells of a phase (least squares, the mean, the partner
    !> of an MMI ghost) or the 2^ndim cells around an image point, which lies in the region,
    !> so within sqrt(ndim) cells of it (3 cells here: a level set is only nearly a distance);
    !> a cell farther (the block's other grains, in a scene of many) is not read: each row is
    !> made from its first cell within reach to its last, a row with none not at all.
    subroutine primitives(pp)
      integer, intent(in) :: pp
      integer :: m, off, ia, ib
      real(wp) :: reach
      off = (pp - 1) * nflow
      reach = 3.0_wp * maxval(lay%dx(1:lay%ndim))
      do k = lo(3), hi(3)
        do j = lo(2), hi(2)
          ! the row's cells from the first to the last within reach
          do ia = lo(1), hi(1)
            if (.not. work%bigphi(ia, j, k, pp) > reach) exit
          end do
          if (ia > hi(1)) cycle
          do ib = hi(1), ia, -1
            if (.not. work%bigphi(ib, j, k, pp) > reach) exit
          end do
          call primitive_row(scn%eos(pp), ib - ia + 1, q(ia:ib, j, k, off+i_rho), &
            q(ia:ib, j, k, off+i_mx), q(ia:ib, j, k, off+i_my), q(ia:ib, j, k, off+i_mz), &
            q(ia:ib, j, k, off+i_en), work%w(ia:ib, j, k, 1, pp), work%w(ia:ib, j, k, 2, pp), &
            work%w(ia:ib, j, k, 3, pp), work%w(ia:ib, j, k, 4, pp), work%w(ia:ib, j, k, 5, pp), &
            work%row)
          do m = n_euler + 1, nflow
            work%w(ia:ib, j, k, m, pp) = q(ia:ib, j, k, off+m) / q(ia:ib, j, k, off+i_rho)
          end do
        end do
      end do
    end subroutine primitives

  end subroutine gfm_fill

  !> True when every cell of the block, halo included, lies beyond the ghost band of every
  !> phase (what gfm_fill calls dormant), from the level sets alone: q's level-set halo must
  !> be current, its flow halo need not be.
  logical function gfm_dormant(lay, scn, set, q, work) result(dormant)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    type(ls_set_t), intent(in) :: set
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    integer :: p, ils
    ils = set%nphase * scn%nflow
    dormant = .true.
    do p = 1, set%nphase
      call ls_region(set, p, 1 - lay%ng, lay%bsize + lay%ng, q(:, :, :, ils+1:ils+set%n), &
        work%bigphi(:, :, :, p), work%owner(:, :, :, p))
      dormant = dormant .and. all(work%bigphi(:, :, :, p) > scn%band)
      if (.not. dormant) return
    end do
  end function gfm_dormant

  !> The ghost band of phase p (work holds every phase's primitives, regions and owners).
  subroutine fill_phase(lay, scn, set, p, q, work, counts, rested)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: p
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    type(gfm_counts_t), intent(inout) :: counts
    logical, intent(in) :: rested   !< as gfm_fill's: no rest state written
    integer :: lo(3), hi(3), i, j, k, npts, d, nd, k3(3), nflow, off, pk, o, m
    real(wp) :: qrest(scn%nflow), grad(3), s(3), wi(scn%nflow), wg(scn%nflow), wk(scn%nflow)
    real(wp) :: c2(1), phi_p, dist, pstar, floor
    logical :: complete, collision
    nflow = scn%nflow
    off = (p - 1) * nflow
    nd = lay%ndim
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    qrest = rest_state(scn%eos(p), nflow, scn%rest(:, p))
    ! the cells beyond the band take the rest state, variable by variable (a cell's variables
    ! lie a block apart: rows that vectorise, every cell stored, as a masked store does not);
    ! nothing below reads them (none where they are in place: rested)
    do m = 1, nflow
      if (rested) exit
      do k = 1, lay%bsize(3)
        do j = 1, lay%bsize(2)
          do i = 1, lay%bsize(1)
            q(i, j, k, off + m) = merge(qrest(m), q(i, j, k, off + m), &
              work%bigphi(i, j, k, p) > scn%band)
          end do
        end do
      end do
    end do
    ! (no associate names for the sections of work: they would start at 1, not at lo)
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        do i = 1, lay%bsize(1)
          phi_p = work%bigphi(i, j, k, p)
          if (phi_p < 0.0_wp .or. phi_p > scn%band) cycle
          counts%ghosts = counts%ghosts + 1
          k3 = [i, j, k]
          grad = levelset_gradient_at(nd, lay%dx, lo, hi, work%bigphi(:, :, :, p), i, j, k)
          if (.not. norm2(grad) > 0.0_wp) grad(1) = 1.0_wp
          grad = grad / norm2(grad)
          ! IP1 at 2 Phi along -n, brought closer where its stencil would leave the padded
          ! block (a ghost near the block's edge): never below Phi, the surface itself
          dist = 2.0_wp * phi_p
          do d = 1, nd
            if (grad(d) > 0.0_wp) dist = min(dist, real(k3(d) - lo(d) - 1, wp) &
              * lay%dx(d) / grad(d))
            if (grad(d) < 0.0_wp) dist = min(dist, real(k3(d) - hi(d) + 1, wp) &
              * lay%dx(d) / grad(d))
          end do
          dist = max(dist, phi_p)
          s = real([i, j, k], wp)
          s(1:nd) = s(1:nd) - dist * grad(1:nd) / lay%dx(1:nd)
          ! an image beyond a region thinner than 2 Phi along the ray (a binder layer thinner
          ! than a cell: outside the region again) goes to the region's deepest point on the
          ! ray, where the probe interpolates the layer's real cells instead of extrapolating
          ! a least-squares fit across the layer (hotspots.md 5, "binder runs away")
          if (probe_scalar(nd, lo, hi, work%bigphi(:, :, :, p), s) >= 0.0_wp) then
            dist = deepest_on_ray(nd, lo, hi, work%bigphi(:, :, :, p), [i, j, k], &
              -grad / lay%dx, phi_p, dist)
            s = real([i, j, k], wp)
            s(1:nd) = s(1:nd) - dist * grad(1:nd) / lay%dx(1:nd)
          end if
          o = work%owner(i, j, k, p)
          pk = 0
          if (o < 0) call partner(-o, pk, collision)
          if (pk > 0) then
            if (.not. partner_state(pk)) pk = 0
          end if
          if (.not. probe_image(work%w(:, :, :, :, p), work%isreal(:, :, :, p), s, pk > 0, &
              wi)) then
            counts%unfilled = counts%unfilled + 1
            q(i, j, k, off+1:off+nflow) = qrest
            cycle
          end if
          if (o > 0) then
            call gfm_mri(nd, grad, set%velocity(:, o), wi, wg)
          else if (pk > 0) then
            call mmi_ghost()
          else
            call gfm_mvi(nd, grad, wi, wg)
          end if
          call eos_sound_speed2(scn%eos(p), 1, wg(1:1), wg(5:5), c2)
          if (.not. (wg(1) > 0.0_wp .and. c2(1) > 0.0_wp)) then
            counts%limited = counts%limited + 1
            wg(1) = max(wg(1), wi(1))
            wg(5) = wi(5)
            call eos_sound_speed2(scn%eos(p), 1, wg(1:1), wg(5:5), c2)
            ! (a condensed material below 1e-3 of its rest density is no state: with the
            ! image's pressure its sound speed is without bound, and so are the fluxes of a
            ! face beside it; a gas may expand that far)
            floor = merge(1.0e-6_wp, 1.0e-3_wp, scn%eos(p)%kind == eos_ideal_gas)
            if (.not. (c2(1) > 0.0_wp .and. wg(1) > floor * scn%rest(1, p))) &
              wg(1:5) = [scn%rest(1, p), wg(2:4), scn%rest(2, p)]
          end if
          call put_state(scn%eos(p), wg, q(i, j, k, off+1:off+nflow))
        end do
      end do
    end do

  contains

    !> the value of this phase at the image point s, by the run's probe; at a contact
    !> (bounded) the least-squares fit kept within its real cells' range
    logical function probe_image(w, isreal, sp, bounded, val) result(found)
      real(wp), intent(in) :: w(lo(1):, lo(2):, lo(3):, :), sp(3)
      logical, intent(in) :: isreal(lo(1):, lo(2):, lo(3):), bounded
      real(wp), intent(out) :: val(:)
      found = .true.
      complete = .false.
      if (scn%probe /= probe_kind_least_squares) then
        call probe_trilinear(nd, lo, hi, w, isreal, sp, val, complete)
        if (complete .or. scn%probe == probe_kind_trilinear) then
          counts%trilinear = counts%trilinear + 1
          if (.not. complete) counts%incomplete = counts%incomplete + 1
          return
        end if
      end if
      ! at a contact every variable within the range of the fit's real cells: an unbounded
      ! linear fit extrapolates (up to three times a mode's size at a corner), and a contact
      ! surface a few hundredths of a cell from a cell centre fed that gain back through the
      ! interface state until the cell ran away (hotspots.md 5, "The junction's loop");
      ! free surfaces and rigid walls keep the linear fit (plastic strain and stored work
      ! bounded), whose reflected ghosts have not been seen to amplify
      call probe_least_squares(nd, lo, hi, w, isreal, sp, val, npts, &
        bounded_from=merge(1, i_epsp, bounded))
      if (npts > 0) counts%least_squares = counts%least_squares + 1
      if (npts < 0) counts%mean = counts%mean + 1
      found = npts /= 0
    end function probe_image

    !> The phase across the surface of material body l at this ghost: for the base phase the
    !> body's phase; for a body, the nearest other body if the gap to it, (phi_l + phi_m) / 2,
    !> is below kappa dx (a collision), else the base phase if it flows, else none (void).
    subroutine partner(l, pp, coll)
      integer, intent(in) :: l
      integer, intent(out) :: pp
      logical, intent(out) :: coll
      integer :: m, ils
      real(wp) :: best
      coll = .false.
      if (set%base_flows .and. p == 1) then
        pp = set%phase(l)
        return
      end if
      ils = set%nphase * nflow
      pp = 0
      best = huge(1.0_wp)
      do m = 1, set%n
        if (set%kind(m) /= ls_material .or. set%phase(m) == p) cycle
        if (q(i, j, k, ils + m) < best) then
          best = q(i, j, k, ils + m)
          pp = set%phase(m)
        end if
      end do
      coll = pp > 0 .and. abs(q(i, j, k, ils + l) + best) < 2.0_wp * scn%contact
      if (coll) return
      pp = 0
      if (set%base_flows) pp = 1
    end subroutine partner

    !> the partner's state at the ghost cell: its own value where the cell is real for it,
    !> else a least-squares fit of its real cells around the cell, bounded as the image's
    logical function partner_state(pp) result(found)
      integer, intent(in) :: pp
      integer :: n
      found = .true.
      if (work%isreal(i, j, k, pp)) then
        wk = work%w(i, j, k, :, pp)
        return
      end if
      call probe_least_squares(nd, lo, hi, work%w(:, :, :, :, pp), work%isreal(:, :, :, pp), &
        real([i, j, k], wp), wk, n, bounded_from=1)
      found = n /= 0
    end function partner_state

    subroutine mmi_ghost()
      real(wp) :: c2k(1), c2i(1), zi, zk
      call eos_sound_speed2(scn%eos(p), 1, wi(1:1), wi(5:5), c2i)
      call eos_sound_speed2(scn%eos(pk), 1, wk(1:1), wk(5:5), c2k)
      if (.not. (c2i(1) > 0.0_wp .and. c2k(1) > 0.0_wp .and. wi(1) > 0.0_wp &
          .and. wk(1) > 0.0_wp)) then
        call gfm_mvi(nd, grad, wi, wg)
        return
      end if
      zi = sqrt(wi(1) * (wi(1) * c2i(1) + 4.0_wp / 3.0_wp * scn%shear(p)))
      zk = sqrt(wk(1) * (wk(1) * c2k(1) + 4.0_wp / 3.0_wp * scn%shear(pk)))
      call gfm_mmi(nd, grad, wi, wk, zi, zk, c2i(1), scn%shear(p) > 0.0_wp, wg, pstar)
      if (collision .and. .not. pstar > 0.0_wp) then
        ! bodies pulling apart: a free surface
        counts%separated = counts%separated + 1
        call gfm_mvi(nd, grad, wi, wg)
        return
      end if
      counts%mmi = counts%mmi + 1
    end subroutine mmi_ghost

  end subroutine fill_phase

  !> Phase p's rest state in every interior cell of the block.
  subroutine put_rest(lay, scn, p, q)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    integer, intent(in) :: p
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp) :: qrest(scn%nflow)
    integer :: m
    qrest = rest_state(scn%eos(p), scn%nflow, scn%rest(:, p))
    do m = 1, scn%nflow
      q(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3), (p - 1) * scn%nflow + m) = qrest(m)
    end do
  end subroutine put_rest

  !> After a stage update: every interior cell outside the computed region goes to the rest
  !> state, so that no stale ghost value is taken for a state (the time step, the
  !> admissibility test and the totals read real cells and rest states only).
  !> absent: phases every cell of which lies beyond their region (m_gfm_stage's phase_rhs):
  !> the rest state in every cell, without their composite level set.
  subroutine gfm_rest(lay, scn, set, q, work, absent)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    type(ls_set_t), intent(in) :: set
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_work_t), intent(inout) :: work
    logical, intent(in), optional :: absent(:)
    integer :: lo(3), hi(3), i, j, k, m, p, off, ils
    real(wp) :: qrest(scn%nflow)
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    ils = set%nphase * scn%nflow
    do p = 1, set%nphase
      off = (p - 1) * scn%nflow
      if (present(absent)) then
        if (absent(p)) then
          call put_rest(lay, scn, p, q)
          cycle
        end if
      end if
      call ls_region(set, p, lo, hi, q(:, :, :, ils+1:ils+set%n), work%bigphi(:, :, :, p), &
        work%owner(:, :, :, p))
      if (all(work%bigphi(1:lay%bsize(1), 1:lay%bsize(2), 1:lay%bsize(3), p) < 0.0_wp)) cycle
      qrest = rest_state(scn%eos(p), scn%nflow, scn%rest(:, p))
      ! variable by variable (a cell's variables lie a block apart): masked rows that vectorise
      do m = 1, scn%nflow
        do k = 1, lay%bsize(3)
          do j = 1, lay%bsize(2)
            do i = 1, lay%bsize(1)
              if (.not. work%bigphi(i, j, k, p) < 0.0_wp) q(i, j, k, off + m) = qrest(m)
            end do
          end do
        end do
      end do
    end do
  end subroutine gfm_rest

  !> Debris: a real cell of a body's phase that the update left inadmissible (rho <= 0,
  !> c^2 <= 0 or not finite) within two cells of the body's surface is a sliver thinner than
  !> the mesh can carry (a fragment or a sheet crushed below a cell). It is taken out of the
  !> body (its level set set to half a cell outside) and holds the rest state; the count goes
  !> to the run log and history.csv, and the body's mass column shows what was lost (lost adds
  !> the mass and energy taken out, per phase, 2 pi r weighted in axisymmetry: the
  !> conservation fix does not put them back). Cells deeper inside, and cells of the base
  !> phase, are left alone: the step's fallback (or its failure) deals with them.
  subroutine gfm_drop_debris(lay, scn, set, offset, q, counts, lost)
    type(layout_t), intent(in) :: lay
    type(gfm_scene_t), intent(in) :: scn
    type(ls_set_t), intent(in) :: set
    integer, intent(in) :: offset(3)
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    type(gfm_counts_t), intent(inout) :: counts
    real(wp), intent(inout) :: lost(:, :)
    integer :: i, j, k, l, p, off, ils
    real(wp) :: w(5), c2(1), e(1), h, dv
    real(wp) :: qrest(scn%nflow)
    ils = set%nphase * scn%nflow
    h = maxval(lay%dx(1:lay%ndim))
    do l = 1, set%n
      if (set%kind(l) /= ls_material) cycle
      p = set%phase(l)
      off = (p - 1) * scn%nflow
      do k = 1, lay%bsize(3)
        do j = 1, lay%bsize(2)
          do i = 1, lay%bsize(1)
            if (.not. (q(i, j, k, ils + l) < 0.0_wp .and. q(i, j, k, ils + l) > -2.0_wp * h)) &
              cycle
            w(1) = q(i, j, k, off + i_rho)
            if (w(1) > 0.0_wp .and. abs(q(i, j, k, off + i_en)) <= huge(1.0_wp)) then
              w(2:4) = q(i, j, k, off + i_mx:off + i_mz) / w(1)
              e(1) = q(i, j, k, off + i_en) / w(1) - 0.5_wp * sum(w(2:4)**2)
              call eos_pressure(scn%eos(p), 1, w(1:1), e, w(5:5))
              call eos_sound_speed2(scn%eos(p), 1, w(1:1), w(5:5), c2)
              if (c2(1) > 0.0_wp .and. c2(1) <= huge(1.0_wp)) cycle
            end if
            counts%debris = counts%debris + 1
            dv = cell_volume(lay, offset, i)
            if (abs(q(i, j, k, off + i_en)) <= huge(1.0_wp)) lost(:, p) = lost(:, p) &
              + dv * [q(i, j, k, off + i_rho), q(i, j, k, off + i_en)]
            qrest = rest_state(scn%eos(p), scn%nflow, scn%rest(:, p))
            q(i, j, k, ils + l) = 0.5_wp * h
            q(i, j, k, off + 1:off + scn%nflow) = qrest
          end do
        end do
      end do
    end do
  end subroutine gfm_drop_debris

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
