!> The conservative cut-cell update of a phase with free surfaces (issue 15, manual/theory.md
!> section 7, manual/interfaces.md section 2c): the phase is updated on its own part of each
!> cell, alpha V, in the manner of Hu, Khoo, Adams and Huang (J. Comput. Phys. 219, 2006).
!> Its content C = alpha U (per cell volume) changes only by the face fluxes times the
!> faces' wet parts (m_euler with cut_faces_t); a free surface exchanges nothing (zero
!> traction, no mass crossing), so the phase's mass, momentum and energy change only by what
!> crosses the domain's sides. The ghost fill is kept for what it is good at: the states of
!> the reconstruction stencils.
!>
!> Between the stages of a step the phase's variables in q hold its content, so that the
!> halo exchange carries content (within near_reach cells of the cells it can reach; deeper in
!> a block's dry part they keep a state, which nothing reads as content and the ghost fill's
!> rest state replaces: m_gfm_cut_box); at the start of each later stage, and once after the
!> last one, cut_open turns content into states: the geometry from the level set (m_levelset_cut),
!> small cells (alpha < small) mixed with their largest face neighbour (the group takes the
!> mean state sum(C V) / sum(alpha V), which keeps every group's content), U = C / alpha.
!> Mixing needs the content and fractions three cells into the halo, which the four-deep
!> halo gives: every block mixes a group the same way, whoever owns it. Content that finds no
!> cell (a cell that the surface has left, with no neighbour to take it) is counted, not
!> hidden (stranded). A small cell alone on an open (outflow) side of the domain holds the
!> last of the phase leaving it: its content goes out through the side (cut%crossed).
!> Between steps q holds states and c0 the content they came from (a
!> wet cell whose centre lies outside the surface shows a ghost or rest state in q; its
!> content is in c0), alpha_n the fractions.
!> Built for one phase whose surfaces are all free (a solid in void, a base material with void
!> bodies); contacts between materials (MMI) and rigid bodies (MRI) still take the ghost-fluid
!> update and the conservation fix (issue 15, what is not built yet: manual/interfaces.md).
module m_gfm_cut
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_state, only: i_rho, i_mx, i_mz, i_en
  use m_euler, only: cut_faces_t
  use m_runge_kutta, only: rk_blend
  use m_gfm_cut_cells, only: mix_lonely, full, debt_mark, full_density, group_roots, ring, on_open
  use m_gfm_cut_close, only: relax_closing, content_sounds
  use m_gfm_cut_geometry, only: cut_block_geometry, wet_reach_box
  use m_gfm_cut_work, only: cut_work_t, fit_work
  use m_gfm_cut_box, only: box_union, box_nonzero, box_whole, box_empty, stage_content, &
    put_states, above_beyond, box_grown
  implicit none
  private
  public :: cut_t, cut_geometry, cut_open, cut_update
  public :: cut_boxes, cut_near, cut_put_boxes

  !> the dry cells kept up to date around the box of the content and the geometry's
  !> (m_gfm_cut_box): the passes read the content only in the box (theirs, the
  !> next open's) and in wet cells, and the surface moves less than a cell in a stage, so that
  !> the next open's box lies within a cell of these; one cell more as a margin
  integer, parameter :: near_reach = 2

  !> a debtor of a small-cell group keeps this part of its fraction's mass at the rest
  !> density when the group repays it (cut_open), so that it takes the group's state and is
  !> not left showing its step-start state
  real(wp), parameter :: debt_trace = 1.0e-3_wp

  !> a contact cell's own density (content over fraction) is blended into the one it takes
  !> where it lies within this part of its neighbours' (reference_density)
  real(wp), parameter :: contact_own = 0.05_wp

  !> A block's fractions over the padded block less its outer layer (for the mixing).
  type :: fraction_t
    real(wp), allocatable :: a(:, :, :)
  end type fraction_t

  !> The cut-cell state: which phase, its content and fractions per block.
  type :: cut_t
    logical :: on = .false.
    logical :: started = .false.                  !< c0 holds the content (the first step on)
    logical :: restored = .false.                 !< c0 was read from a checkpoint
    logical :: restored_fractions = .false.       !< alpha_n and ext_n were too
    character(len=256) :: reason = ''
    integer :: p = 0                              !< the cut phase
    real(wp) :: small = 0.5_wp                    !< cells below this fraction are mixed
    real(wp) :: follow = 1.0_wp                   !< gain of a void's level set towards content
    !> a material body's level set follows its content where they differ by more than this
    !> (fraction of a cell; &numerics body_follow; 0: not at all): m_gfm_cut_close
    real(wp) :: body_dead = 0.0_wp
    type(cut_faces_t), allocatable :: faces(:)    !< (block) geometry of the current stage
    type(fraction_t), allocatable :: ext(:)       !< (block) its fractions into the halo
    type(fraction_t), allocatable :: ext_n(:)     !< (block) the same at the last step's end
    real(wp), allocatable :: c(:, :, :, :, :)     !< (cell, variable, block) content, stage
    real(wp), allocatable :: c0(:, :, :, :, :)    !< (cell, variable, block) at the step start
    real(wp), allocatable :: alpha_n(:, :, :, :)  !< (cell, block) fractions of q's states
    real(wp) :: stranded(2) = 0.0_wp              !< mass, energy that found no cell (so far)
    real(wp) :: crossed(2) = 0.0_wp               !< mass, energy in through the sides (so far)
    real(wp) :: exchanged = 0.0_wp                !< energy in through contacts (so far)
    !> this step's, per block (summed over the blocks by id at the step's end, so that the
    !> totals above are the same on every rank and on any number of ranks):
    real(wp), allocatable :: side(:, :, :)        !< (mass, energy through the sides, energy
                                                  !< through contacts; stage; block) rates in
    real(wp), allocatable :: out(:, :)            !< (crossed out: mass, energy; stranded:
                                                  !< mass, energy; closing: cells, heat;
                                                  !< held cells; block) by the cell rules
    real(wp) :: closing(2) = 0.0_wp               !< closing cells (cell-steps), their heat
    real(wp) :: held = 0.0_wp                     !< drained full cells given a cut cell's
                                                  !< density (cell-stages)
    !> cell-stages whose contact with a later cut phase exchanged traction and work (this
    !> rank's, m_gfm_cut_contact)
    integer :: contacts = 0
    !> cell-stages of a cell in debt (its fluxes drew out more mass than it held) that its
    !> small-cell group repaid, and that no group could (this rank's; run.log)
    integer :: debts(2) = 0
    !> cell-stages of a small cell that no group held, mixed with its ring (this rank's;
    !> m_gfm_cut_cells' mix_lonely; run.log)
    integer :: lonely = 0
    !> cell-stages of a small cell whose content sounds at no density it may take (run.log)
    integer :: soundless = 0
    type(cut_work_t) :: work                      !< scratch of the stage's passes (any block)
    !> (2, 3, block) boxes (m_gfm_cut_box) of this stage: the cells beyond which the content
    !> c is zero (boxed: made by cut_update, which scans c0 at a step's first stage), the
    !> cells whose rate phase_rhs computed (beyond: +0), the cells the geometry cut
    integer, allocatable :: box(:, :, :), rate_box(:, :, :), wet_box(:, :, :)
    !> (2, 3, block) the box near which cut_update wrote q (its box and geo_box: the dry
    !> cells near it hold zero content until the next open puts their states)
    integer, allocatable :: near_box(:, :, :)
    !> (2, 3, block) the wet box before it is cut to the block's cells: where it lies in the
    !> halo, the cells the surface may reach from a neighbour within a stage
    integer, allocatable :: geo_box(:, :, :)
    !> (2, 3, block) the cells whose states in q the last open put (beyond it q is as the
    !> halo exchange before the open found it): what its neighbours' halos take again
    integer, allocatable :: put_box(:, :, :)
    logical, allocatable :: boxed(:)
    !> (block) its geometry is that of the level sets as they are: made at the last step's
    !> end, and nothing has moved them since (no void's surface followed its content, no
    !> reinitialisation: m_step_after), so the next step's first stage takes it as it is
    logical, allocatable :: kept(:)
    !> (block) it woke at this stage, after the geometry was made (m_gfm_stage)
    logical, allocatable :: woke(:)
  end type cut_t

contains

  !> The geometry of the cut phase on block blk from its composite level set bigphi (over
  !> the padded block): the interior faces' apertures and fractions into cut%faces(b), and
  !> the fractions alpha_e over the padded block less its outer layer (for the mixing); the
  !> block's cells that may be wet into cut%wet_box.
  subroutine cut_geometry(cut, b, blk, bigphi, open_side, alpha_e)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(in) :: blk
    real(wp), intent(in) :: bigphi(:, :, :)
    logical, intent(in) :: open_side(2, 3)   !< the domain's outflow sides
    real(wp), allocatable, intent(inout) :: alpha_e(:, :, :)
    integer :: box(2, 3)
    call cut_block_geometry(cut%work, blk%lay, blk%offset, blk%n, bigphi, open_side, &
      cut%faces(b), alpha_e, box)
    cut%wet_box(1, :, b) = max(box(1, :), 1)
    cut%wet_box(2, :, b) = min(box(2, :), blk%n)
    ! (with the cells the surface may wet before the next open, however far from these)
    cut%geo_box(:, :, b) = box_union(box, wet_reach_box(blk%lay, blk%n, bigphi))
  end subroutine cut_geometry

  !> Content into states on block blk (number b), after the halo exchange: q's phase
  !> variables hold the content C over the padded block; the small cells are mixed, the
  !> interior's content kept in cut%c and its states U = C / alpha put into q. failed: a
  !> state with rho <= 0 or an energy that is not finite. Beyond box (m_gfm_cut_box) every
  !> cell is dry and its content +0 in q and in cut%c: it takes the step start's state.
  subroutine cut_open(cut, b, blk, ph, alpha_e, open_side, final, failed, bigphi, owner, box, &
      band, touch)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    real(wp), intent(in) :: alpha_e(:, :, :)
    logical, intent(in) :: open_side(2, 3)   !< the domain's outflow sides (low, high; x, y, z)
    logical, intent(in) :: final             !< at the step's end (after its last stage)
    logical, intent(inout) :: failed
    real(wp), intent(in) :: bigphi(:, :, :)   !< the phase's level set over the padded block
    integer, intent(in) :: owner(:, :, :)     !< whose surface (ls_region; 0: a void's)
    integer, intent(in) :: box(2, 3)
    real(wp), intent(in) :: band              !< the ghost band's width (m_gfm)
    !> (interior cells) another cut phase wets the cell: a contact
    logical, intent(in) :: touch(:, :, :)
    real(wp), allocatable :: vol(:)
    integer :: kind(blk%n(1), blk%n(2), blk%n(3))
    logical :: member(blk%n(1), blk%n(2), blk%n(3))
    integer :: e(3), n(3), g(3), i, j, k, lo, nf, m
    real(wp) :: cc(ph%nflow), tally(2), rho
    logical :: relaxed
    lo = ph%lo(cut%p)
    nf = ph%nflow
    associate (lay => blk%lay, q => blk%q)
      n = blk%n
      e = max(lay%ng - 1, 0)
      allocate(vol(1-e(1):n(1)+e(1)))
      do i = 1 - e(1), n(1) + e(1)
        vol(i) = cell_volume(lay, blk%offset, i)
      end do
      ! the content as it came is q's phase variables; where cells close, the closing cells'
      ! exchange puts what it gives in cut%work%relaxed (the closing cells' tally accumulates
      ! onto the block's, cut%out(5:6, b))
      tally = 0.0_wp
      if (allocated(cut%out)) tally = cut%out(5:6, b)
      call relax_closing(lay, blk%offset, n, e, alpha_e, bigphi, owner, final, &
        q(:, :, :, lo:lo + nf - 1), cut%work%relaxed, tally, relaxed)
      if (allocated(cut%out)) cut%out(5:6, b) = tally
      ! the contents (cut%c) from it, read in place: nothing writes q until they are made
      if (relaxed) then
        call contents(cut%work%relaxed)
      else
        call contents(q(:, :, :, lo:lo + nf - 1))
      end if
      ! the states: a full cell's its content over its fraction; a cell with no material
      ! (outside, or a wet cell that nothing has reached yet, with no neighbour to share
      ! with) the state it had at the step's start (a ghost or rest state, which the ghost
      ! fill and m_gfm's rest state replace; its content is kept in cut%c); a cut cell's
      ! below
      ! (each cell's kind once: 0 the start's state, 1 full, 2 cut; then variable by variable)
      kind = 0
      do k = box(1, 3), box(2, 3)
        do j = box(1, 2), box(2, 2)
          do i = box(1, 1), box(2, 1)
            kind(i, j, k) = 0
            if (alpha(i, j, k) > 0.0_wp .and. cut%c(i, j, k, i_rho, b) > 0.0_wp) then
              kind(i, j, k) = merge(2, 1, alpha(i, j, k) < full)
            end if
          end do
        end do
      end do
      ! a full cell beside the surface (or below half the rest density) whose content has
      ! no real sound speed at its own density (drained: the level set of a material body
      ! drifts ahead of its content, theory.md 7c) takes a cut cell's density, so that the
      ! drift stays a partly filled cell rather than a tension no material holds; counted at
      ! every stage (history.csv cut_held_cells)
      do k = box(1, 3), box(2, 3)
        do j = box(1, 2), box(2, 2)
          do i = box(1, 1), box(2, 1)
            if (kind(i, j, k) /= 1) cycle
            if (.not. beside_surface([i, j, k]) .and. &
              cut%c(i, j, k, i_rho, b) > 0.5_wp * ph%rest(1, cut%p)) cycle
            if (content_sounds(ph%eos(cut%p), cut%c(i, j, k, i_rho, b), &
              cut%c(i, j, k, 1:nf, b))) cycle
            kind(i, j, k) = 2
            if (allocated(cut%out)) cut%out(7, b) = cut%out(7, b) + 1.0_wp
          end do
        end do
      end do
      ! the dry cells whose states are put: those near the box or near where the stage's
      ! update wrote zero content (cut_update); the others (deep in the dry part) keep
      ! theirs only where the ghost fill puts the rest state on them next (beyond the band:
      ! m_gfm's gfm_fill, gfm_rest at the step's end), which nothing reads before; otherwise
      ! all
      g = lay%ng
      cut%put_box(:, :, b) = box_grown(box_union(box, cut%near_box(:, :, b)), near_reach, n)
      if (.not. above_beyond(cut%put_box(:, :, b), bigphi(1+g(1):n(1)+g(1), &
        1+g(2):n(2)+g(2), 1+g(3):n(3)+g(3)), band)) cut%put_box(:, :, b) = box_whole(n)
      do m = 1, nf
        if (final) then
          do k = box(1, 3), box(2, 3)
            do j = box(1, 2), box(2, 2)
              where (.not. alpha_e(box(1, 1)+e(1):box(2, 1)+e(1), j + e(2), k + e(3)) > 0.0_wp) &
                cut%c(box(1, 1):box(2, 1), j, k, m, b) = 0.0_wp
            end do
          end do
        end if
        call put_states(box, cut%put_box(:, :, b), kind, &
          alpha_e(1+e(1):n(1)+e(1), 1+e(2):n(2)+e(2), 1+e(3):n(3)+e(3)), &
          cut%c(1:n(1), 1:n(2), 1:n(3), m, b), blk%q0(:, :, :, lo + m - 1), &
          q(1:n(1), 1:n(2), 1:n(3), lo + m - 1))
      end do
      do k = box(1, 3), box(2, 3)
        do j = box(1, 2), box(2, 2)
          do i = box(1, 1), box(2, 1)
            if (kind(i, j, k) == 2) then
              ! a cut cell (or a drained full cell): its content per mass at the density of
              ! the material beside it; a cell small by fraction or content that sounds at no
              ! density shows its step-start state; at the step's end its content is stranded
              cc = cut%c(i, j, k, 1:nf, b)
              rho = reference_density([i, j, k], cc)
              if (rho > 0.0_wp) then
                q(i, j, k, lo:lo + nf - 1) = cc * (rho / cc(i_rho))
              else if (min(alpha(i, j, k), cc(i_rho) / ph%rest(1, cut%p)) < cut%small) then
                cut%soundless = cut%soundless + 1
                q(i, j, k, lo:lo + nf - 1) = blk%q0(i, j, k, lo:lo + nf - 1)
                if (final) then
                  cut%out(3, b) = cut%out(3, b) + cc(i_rho) * vol(i)
                  cut%out(4, b) = cut%out(4, b) + cc(i_en) * vol(i)
                  cut%c(i, j, k, 1:nf, b) = 0.0_wp
                end if
              else
                q(i, j, k, lo:lo + nf - 1) = cc * (-rho / cc(i_rho))
              end if
            end if
            if (kind(i, j, k) > 0) then
              if (.not. admissible(q(i, j, k, lo:lo + nf - 1))) failed = .true.
            end if
          end do
        end do
      end do
    end associate

  contains

    !> The interior's contents into cut%c from the content cq over the padded block: each
    !> cell its own, then the cells the rules below change (an empty cell, the members of a
    !> group, the last of the phase on an open side); the mass content kept aside
    !> (cut%work%rho) for the cut cells' densities, which are made after q holds states.
    subroutine contents(cq)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      integer :: ii, jj, kk, r(3), mm, rl(3), rh(3), l
      real(wp) :: sum_c(ph%nflow), sum_a, least
      call fit_work(cut%work%rho, 1 - blk%lay%ng, n + blk%lay%ng)
      ! (full_density reads it within two cells of a cut cell of the box)
      if (all(box(1, :) <= box(2, :))) then
        rl = max(box(1, :) - 2, 1 - blk%lay%ng)
        rh = min(box(2, :) + 2, n + blk%lay%ng)
        cut%work%rho(rl(1):rh(1), rl(2):rh(2), rl(3):rh(3)) = &
          cq(rl(1):rh(1), rl(2):rh(2), rl(3):rh(3), i_rho)
      end if
      ! the fractions the groups are formed by: a wet cell whose content fills less of it
      ! than its fraction says (a surface the level set has moved ahead of the material, as
      ! where a void closes) counts by its content, at the phase's rest density; a wet cell
      ! whose fluxes drew out more mass than it held (a debt) counts as the smallest of
      ! small cells (debt_mark), so that it joins a group and the group repays it (below):
      ! alone, it would show its step-start state at every stage while the fluxes went on
      ! drawing from it (the frozen cell of interfaces.md 2d)
      call fit_work(cut%work%filled, [1, 1, 1], shape(alpha_e))
      associate (filled => cut%work%filled)
        do kk = 1, size(alpha_e, 3)
          do jj = 1, size(alpha_e, 2)
            do ii = 1, size(alpha_e, 1)
              filled(ii, jj, kk) = alpha_e(ii, jj, kk)
              if (.not. alpha_e(ii, jj, kk) > 0.0_wp) cycle
              if (cq(ii - e(1), jj - e(2), kk - e(3), i_rho) < 0.0_wp) then
                filled(ii, jj, kk) = debt_mark
              else
                filled(ii, jj, kk) = min(alpha_e(ii, jj, kk), &
                  cq(ii - e(1), jj - e(2), kk - e(3), i_rho) / ph%rest(1, cut%p))
              end if
            end do
          end do
        end do
      end associate
      call group_roots(blk%lay, blk%offset, n, e, cut%work%filled, cut%small, cut%work%root)
      associate (root => cut%work%root)
        ! the roots some neighbour has joined (only a small cell joins, and only a ring
        ! neighbour of its root)
        member = .false.
        do kk = lbound(root, 4), ubound(root, 4)
          do jj = lbound(root, 3), ubound(root, 3)
            do ii = lbound(root, 2), ubound(root, 2)
              r = root(:, ii, jj, kk)
              if (all(r == [ii, jj, kk]) .or. any(r < 1 .or. r > n)) cycle
              member(r(1), r(2), r(3)) = .true.
            end do
          end do
        end do
        ! (beyond the box both are +0 already, and a dry cell there has nothing to count)
        do mm = 1, nf
          cut%c(box(1, 1):box(2, 1), box(1, 2):box(2, 2), box(1, 3):box(2, 3), mm, b) = &
            cq(box(1, 1):box(2, 1), box(1, 2):box(2, 2), box(1, 3):box(2, 3), mm)
        end do
        do kk = box(1, 3), box(2, 3)
          do jj = box(1, 2), box(2, 2)
            do ii = box(1, 1), box(2, 1)
              r = root(:, ii, jj, kk)
              if (.not. alpha(ii, jj, kk) > 0.0_wp) then
                ! empty: what content it still holds found no wet neighbour (cut_donate); it
                ! is taken out (and counted) at the step's end only, where the budget sees
                ! it once (inside the step a stage's content counts with the stage's weight)
                if (final) then
                  cut%out(3, b) = cut%out(3, b) + cq(ii, jj, kk, i_rho) * vol(ii)
                  cut%out(4, b) = cut%out(4, b) + cq(ii, jj, kk, i_en) * vol(ii)
                end if
              else if (all(r == [ii, jj, kk]) .and. .not. member(ii, jj, kk)) then
                if (cq(ii, jj, kk, i_rho) < 0.0_wp) cut%debts(2) = cut%debts(2) + 1
                if (final .and. alpha(ii, jj, kk) < cut%small &
                  .and. on_open(blk%lay, blk%offset, open_side, [ii, jj, kk])) then
                  ! a small cell alone on an open side: the last of the phase leaving the
                  ! domain; what it holds goes out through the side (counted)
                  cut%out(1, b) = cut%out(1, b) - cq(ii, jj, kk, i_rho) * vol(ii)
                  cut%out(2, b) = cut%out(2, b) - cq(ii, jj, kk, i_en) * vol(ii)
                  cut%c(ii, jj, kk, 1:nf, b) = 0.0_wp
                end if
              else
                call group_sum(cq, r, sum_c, sum_a, least)
                if (cq(ii, jj, kk, i_rho) < 0.0_wp) then
                  l = merge(1, 2, sum_c(i_rho) > 0.0_wp)
                  cut%debts(l) = cut%debts(l) + 1
                end if
                if (least > 0.0_wp) then
                  ! every member keeps its mass and takes the group's state per mass
                  cut%c(ii, jj, kk, 1:nf, b) = cq(ii, jj, kk, i_rho) * sum_c / sum_c(i_rho)
                else if (sum_c(i_rho) > 0.0_wp) then
                  ! a member has lost more mass than it held (a debt): the others repay it
                  ! in proportion to the mass they hold, the debtor keeps a trace (debt_trace
                  ! of its fraction's mass at the rest density), and every member takes the
                  ! group's state per mass (sum_a: the members' weights, group_sum)
                  cut%c(ii, jj, kk, 1:nf, b) = sum_c * (max(cq(ii, jj, kk, i_rho), 0.0_wp) &
                    + debt_trace * alpha(ii, jj, kk) * ph%rest(1, cut%p)) / sum_a
                end if
              end if
            end do
          end do
        end do
      end associate
      ! the small cells that no group holds, mixed with their rings (after the groups)
      call mix_lonely(blk%lay, blk%offset, e, alpha_e, cut%work%filled, cut%work%root, &
        cut%small, cq, box, cut%c(:, :, :, :, b), cut%lonely)
    end subroutine contents

    real(wp) function alpha(i0, j0, k0)
      integer, intent(in) :: i0, j0, k0
      alpha = alpha_e(i0 + e(1), j0 + e(2), k0 + e(3))
    end function alpha

    !> The density a cut cell c0 takes: that of the full cells beside it (full_density),
    !> else (a sliver with no full cell near) the density it had at the step's start (its
    !> state, or the ghost state beside the phase of a cell just reached), else its own
    !> content over its fraction, else the phase's rest density: the first of these at which
    !> the content's energy per mass gives a real sound speed (a sliver whose level set
    !> encloses much more than its content fills would otherwise be put in deep tension,
    !> c^2 < 0: the foot of the 400 m/s Taylor bar at 28.7 us, 0.62 rho0 at -77 GPa).
    !> In a contact cell (touch: another cut phase wets it) the first goes over from the
    !> neighbours' density at fraction `small` to the cell's own content over its fraction
    !> at 1, where the cell, full, takes its content as it is (contact_own; theory.md 7e):
    !> the traction of a contact is made from this state, and a full cell beside a moving
    !> contact is a shocked cell whose compression a neighbour's density would hide until
    !> it filled, then release at once (the pulse at every cell crossing of
    !> interfaces.md 2d). Only where its own density is within contact_own of the
    !> neighbours': beyond that the level set, not the compression, is what differs.
    !> Minus its own content over its fraction where none of them sounds.
    real(wp) function reference_density(c0, cc0) result(rho)
      integer, intent(in) :: c0(3)
      real(wp), intent(in) :: cc0(:)
      real(wp) :: cand(4), w
      integer :: l
      cand(1) = full_density(blk%lay, blk%offset, e, alpha_e, cut%work%rho, c0)
      cand(2) = blk%q0(c0(1), c0(2), c0(3), lo + i_rho - 1)
      cand(3) = cc0(i_rho) / alpha(c0(1), c0(2), c0(3))
      cand(4) = ph%rest(1, cut%p)
      rho = -cand(3)
      w = (alpha(c0(1), c0(2), c0(3)) - cut%small) / (1.0_wp - cut%small)
      if (touch(c0(1), c0(2), c0(3)) .and. w > 0.0_wp .and. cand(1) > 0.0_wp) then
        if (abs(cand(3) - cand(1)) < contact_own * cand(1)) &
          cand(1) = (1.0_wp - w) * cand(1) + w * cand(3)
      end if
      do l = 1, 4
        if (.not. cand(l) > 0.0_wp) cycle
        if (.not. content_sounds(ph%eos(cut%p), cand(l), cc0)) cycle
        rho = cand(l)
        return
      end do
    end function reference_density

    !> whether a face neighbour of interior cell c0 is not full (the surface is beside it;
    !> asked of every full cell of the box, so without temporaries)
    logical function beside_surface(c0)
      integer, intent(in) :: c0(3)
      integer :: d, s, m(3)
      beside_surface = .true.
      do d = 1, blk%lay%ndim
        do s = -1, 1, 2
          m = c0
          m(d) = c0(d) + s
          if (alpha(m(1), m(2), m(3)) < full) return
        end do
      end do
      beside_surface = .false.
    end function beside_surface

    !> The content (times volume) of the group of root c0: c0 and the neighbours that joined
    !> it (faces first, then edges and corners); sa the members' weights for repaying a debt,
    !> sum of (max(mass content, 0) + debt_trace alpha rho_rest) V.
    subroutine group_sum(cq, c0, sc, sa, least)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      integer, intent(in) :: c0(3)
      real(wp), intent(out) :: sc(:), sa
      real(wp), intent(out) :: least   !< the smallest mass content of a member
      integer :: nb(3, 26), l, nl
      sc = cq(c0(1), c0(2), c0(3), :) * vol(c0(1))
      sa = weight(cq, c0)
      least = cq(c0(1), c0(2), c0(3), i_rho)
      call ring(blk%lay%ndim, c0, nb, nl)
      do l = 1, nl
        if (.not. all(cut%work%root(:, nb(1, l), nb(2, l), nb(3, l)) == c0)) cycle
        sc = sc + cq(nb(1, l), nb(2, l), nb(3, l), :) * vol(nb(1, l))
        sa = sa + weight(cq, nb(:, l))
        least = min(least, cq(nb(1, l), nb(2, l), nb(3, l), i_rho))
      end do
    end subroutine group_sum

    !> a member's weight in repaying its group's debt (group_sum)
    real(wp) function weight(cq, c1)
      real(wp), intent(in) :: cq(1-blk%lay%ng(1):, 1-blk%lay%ng(2):, 1-blk%lay%ng(3):, :)
      integer, intent(in) :: c1(3)
      weight = (max(cq(c1(1), c1(2), c1(3), i_rho), 0.0_wp) &
        + debt_trace * alpha(c1(1), c1(2), c1(3)) * ph%rest(1, cut%p)) * vol(c1(1))
    end function weight

    logical function admissible(u)
      real(wp), intent(in) :: u(:)
      ! (the internal energy of a solid may be zero or below at its reference state)
      admissible = u(i_rho) > 0.0_wp .and. abs(u(i_en)) <= huge(1.0_wp)
    end function admissible
  end subroutine cut_open

  !> After the stage update of block b: the phase's content C = a C0 + b (C + dt R) (the
  !> TVD Runge-Kutta weights of the stage), R the content rate that euler_rhs gave with the
  !> cut faces (in rhs), C0 the content at the step's start (the last open of the step
  !> before). The content goes into q's phase variables (interior), for the halo exchange
  !> before the next open.
  subroutine cut_update(cut, b, blk, ph, stage, order, dt)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: b, stage, order
    type(block_t), intent(inout) :: blk
    type(phases_t), intent(in) :: ph
    real(wp), intent(in) :: dt
    real(wp) :: a
    integer :: lo, n(3), m, pb(2, 3), nz(2, 3), near(2, 3)
    lo = ph%lo(cut%p)
    n = blk%n
    a = 0.0_wp
    if (stage > 1) a = rk_blend(stage, order)
    ! the content's box: at a step's first stage that of c0 (a restart, a rebalance or a
    ! block that woke may have brought it: the whole block scanned; else c0 is zero beyond
    ! the box of the step before, which alone is), then what the stages and opens added
    if (stage == 1) then
      pb = box_whole(n)
      if (cut%boxed(b)) pb = cut%box(:, :, b)
      cut%box(:, :, b) = box_empty
      if (all(pb(1, :) <= pb(2, :))) then
        nz = box_nonzero(cut%c0(pb(1, 1):pb(2, 1), pb(1, 2):pb(2, 2), pb(1, 3):pb(2, 3), :, b))
        if (all(nz(1, :) <= nz(2, :))) cut%box(:, :, b) = nz + spread(pb(1, :) - 1, 1, 2)
      end if
    else if (.not. cut%boxed(b)) then
      cut%box(:, :, b) = box_whole(n)
    end if
    cut%box(:, :, b) = box_union(cut%box(:, :, b), cut%rate_box(:, :, b))
    cut%boxed(b) = .true.
    ! (the dry cells deep in the block keep their states: m_gfm_cut_box; the next open reads
    ! the content over this box and the cells the surface may wet then, which lie within a
    ! cell of those it may wet now, in the block or in its halo: geo_box)
    cut%near_box(:, :, b) = box_union(cut%box(:, :, b), cut%geo_box(:, :, b))
    ! (a block that woke at this stage has no wet box of this stage: every cell)
    if (cut%woke(b)) cut%near_box(:, :, b) = box_whole(n)
    cut%woke(b) = .false.
    near = box_grown(cut%near_box(:, :, b), near_reach, n)
    ! (variable by variable, the content and q's copy of it in one pass)
    do m = 1, ph%nflow
      call stage_content(stage == 1, a, dt, cut%box(:, :, b), near, &
        cut%c0(1:n(1), 1:n(2), 1:n(3), m, b), blk%rhs(:, :, :, lo + m - 1), &
        cut%c(1:n(1), 1:n(2), 1:n(3), m, b), blk%q(1:n(1), 1:n(2), 1:n(3), lo + m - 1))
    end do
  end subroutine cut_update

  !> The cells of block b (of n cells) whose phase variables in q the last cut_update may
  !> have written (beyond them q holds what it held before the update)
  pure function cut_near(cut, b, n) result(box)
    type(cut_t), intent(in) :: cut
    integer, intent(in) :: b, n(3)
    integer :: box(2, 3)
    box = box_grown(cut%near_box(:, :, b), near_reach, n)
  end function cut_near

  !> The boxes sized for nb blocks, none boxed: at the setup, and again when the blocks
  !> changed (m_rebalance), since a block's box is its own.
  subroutine cut_boxes(cut, nb)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: nb
    if (allocated(cut%boxed)) deallocate(cut%box, cut%rate_box, cut%wet_box, cut%near_box, &
      cut%put_box, cut%boxed, cut%kept, cut%woke, cut%geo_box)
    allocate(cut%box(2, 3, nb), cut%rate_box(2, 3, nb), cut%wet_box(2, 3, nb), &
      cut%near_box(2, 3, nb), cut%put_box(2, 3, nb), cut%boxed(nb), cut%kept(nb), &
      cut%woke(nb), cut%geo_box(2, 3, nb))
    cut%geo_box(1, :, :) = 1   ! (none)
    cut%geo_box(2, :, :) = 0
    cut%kept = .false.
    cut%woke = .false.
    cut%put_box = 0
    cut%box = 0
    cut%rate_box = 0
    cut%wet_box = 0
    cut%near_box(1, :, :) = 1   ! (none)
    cut%near_box(2, :, :) = 0
    cut%boxed = .false.
  end subroutine cut_boxes

  !> Each block's box of the cells whose states the last open put (cut_t's put_box), over
  !> every cut phase.
  pure function cut_put_boxes(cut, nb) result(box)
    type(cut_t), intent(in) :: cut(:)
    integer, intent(in) :: nb
    integer :: box(2, 3, nb), b, k
    do b = 1, nb
      box(:, :, b) = cut(1)%put_box(:, :, b)
      do k = 2, size(cut)
        box(:, :, b) = box_union(box(:, :, b), cut(k)%put_box(:, :, b))
      end do
    end do
  end function cut_put_boxes

end module m_gfm_cut
