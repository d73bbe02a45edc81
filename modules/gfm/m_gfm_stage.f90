!> The phases' part of a Runge-Kutta stage, with their surfaces where the scene has them
!> (DESIGN section 5, manual/interfaces.md): the ghost-fluid fill before the right-hand
!> sides, each phase's right-hand side on a block, and each phase's corrections after the
!> update. A scene without level sets goes straight to the bulk kernels (m_euler,
!> m_elastoplastic) and pays nothing for surfaces. The driver (src/m_step.f90) strings these
!> together; a conservative interface update changes them here.
module m_gfm_stage
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_blocks, only: block_t
  use m_halo, only: halo_plan_t
  use m_boundary, only: bc_kind_t, fill_ghosts, ghosts_flow, refresh_ghosts
  use m_phases, only: phases_t
  use m_config, only: body_t
  use m_euler, only: numerics_t, euler_work_t, euler_rhs
  use m_runge_kutta, only: rk_weights
  use m_elastoplastic, only: plastic_correction
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_separate, ls_material, ls_void
  use m_scene, only: rigid_bodies_move, made_t
  use m_gfm, only: gf_t, gf_fit, gfm_fill, gfm_rest, gfm_drop_debris, gfm_dormant
  use m_gfm_conserve, only: fix_t
  use m_gfm_cut, only: cut_t, cut_geometry, cut_open, cut_update, cut_near, cut_put_boxes
  use m_gfm_cut_budget, only: cut_strand, cut_scalars
  use m_gfm_cut_box, only: box_union, box_whole, box_below, box_empty
  use m_tiles, only: near_boxes, tile_cells
  use m_gfm_cut_close, only: cut_follow, cut_follow_body
  use m_gfm_cut_cells, only: cut_donate
  use m_gfm_cut_contact, only: cut_contact
  use m_state, only: n_euler, i_rho
  use m_boundary, only: ghosts_all, ghosts_level_sets, bc_outflow
  use m_comm, only: comm_any, comm_sum_by_key
  implicit none
  private
  public :: ghost_fluid_fill, phase_rhs, phase_corrections, phase_states

  !> what phase_states does (see there)
  integer, parameter, public :: states_geometry = 0, states_open = 1, states_end = 2, &
    states_start = 3

contains

  !> The ghost-fluid stage at time t (DESIGN section 5): rigid level sets moved to t, ghost
  !> bands filled on every block (m_gfm). The caller then fills the flow ghosts again
  !> (m_boundary's fill_ghosts, dormant blocks skipped) so that each block sees its
  !> neighbours' ghosts. A dormant block (every cell, halo included, beyond every band) is not
  !> computed, and its flow halo is not kept. Before any fill, a block that was dormant and
  !> wakes (its level sets, always exchanged, now reach into a band) takes the flow halo it
  !> missed, from neighbours not yet filled: the result is that of exchanging every halo
  !> every time.
  !> With a cut-cell phase (m_gfm_cut), first its geometry at this stage and, after the first
  !> stage, its content into states (and their radial return); failed: a state that is not
  !> admissible.
  subroutine ghost_fluid_fill(gf, cut, ls, ph, plan, lay, bc, bodies, made, blocks, t, stage, &
      dt, thermal, failed)
    type(gf_t), intent(inout) :: gf
    type(cut_t), intent(inout) :: cut(:)   !< one for each cut phase (m_gfm_cut_setup)
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(body_t), intent(in) :: bodies(:)
    type(made_t), intent(in) :: made(:)
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: t, dt
    integer, intent(in) :: stage
    logical, intent(in) :: thermal
    logical, intent(inout) :: failed
    integer :: b, k
    call rigid_bodies_move(lay, bodies, made, ls, ph%ils, blocks, t)
    if (cut(1)%on) then
      if (stage == 1) then
        ! this step's budget per block (a step that is redone starts it again)
        do k = 1, size(cut)
          if (allocated(cut(k)%side)) deallocate(cut(k)%side, cut(k)%out)
          allocate(cut(k)%side(3, 3, size(blocks)), cut(k)%out(7, size(blocks)))
          cut(k)%side = 0.0_wp
          cut(k)%out = 0.0_wp
        end do
      end if
      call phase_states(gf, cut, ls, ph, plan, lay, bc, blocks, t, dt, 0, thermal, &
        merge(states_open, states_geometry, stage > 1), failed)
      ! the halo held content: now the neighbours' states, for the ghost fill's stencils
      if (stage > 1) call states_halo()
    end if
    ! (after the cut-cell phase's content is states again: a waking block copies states)
    do b = 1, size(blocks)
      if (.not. gf%dormant(b)) cycle
      call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
      if (gfm_dormant(blocks(b)%lay, gf%scn, ls, blocks(b)%q, gf%work)) cycle
      call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_flow, t, only=b)
      ! (its cut-cell geometry was not made at this stage: cut_update keeps every cell; a
      ! phase that never had a geometry on it, as where a block wakes for another cut
      ! phase, takes one now, with no fractions at the last step's end)
      do k = 1, size(cut)
        if (.not. cut(k)%on) cycle
        cut(k)%woke(b) = .true.
        if (allocated(cut(k)%ext(b)%a)) cycle
        associate (blk => blocks(b), p => cut(k)%p)
          call ls_region(ls, p, 1 - blk%lay%ng, blk%n + blk%lay%ng, &
            blk%q(:, :, :, ph%ils + 1:ph%nvar), gf%work%bigphi(:, :, :, p), &
            gf%work%owner(:, :, :, p))
          call cut_geometry(cut(k), b, blk, gf%work%bigphi(:, :, :, p), &
            reshape([bc%lo == bc_outflow, bc%hi == bc_outflow], [2, 3], order=[2, 1]), &
            cut(k)%ext(b)%a)
          if (allocated(cut(k)%ext_n(b)%a)) deallocate(cut(k)%ext_n(b)%a)
          allocate(cut(k)%ext_n(b)%a, mold=cut(k)%ext(b)%a)
          cut(k)%ext_n(b)%a = 0.0_wp
        end associate
      end do
    end do
    if (.not. allocated(gf%rested)) allocate(gf%rested(size(blocks)), source=.false.)
    do b = 1, size(blocks)
      call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
      call gfm_fill(blocks(b)%lay, gf%scn, ls, blocks(b)%q, gf%work, gf%counts, gf%dormant(b), &
        rested=gf%rested(b) .and. .not. cut(1)%on)
      gf%rested(b) = gf%dormant(b)
      if (gf%dormant(b)) cycle
      do k = 1, size(cut)
        if (cut(k)%on) call cut_scalars(cut(k), b, blocks(b), ph, stage)
      end do
    end do

  contains

    !> The states the open put, into the halos: on one rank only the cells it wrote
    !> (cut%put_box; the rest of every halo holds what the exchange before the open gave it,
    !> which is what it has), m_boundary's refresh_ghosts; the whole flow fill otherwise.
    subroutine states_halo()
      if (comm_any(any(plan%remote))) then
        call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_flow, t, gf%dormant)
      else
        call refresh_ghosts(plan, lay, bc, blocks, ph, cut_put_boxes(cut, size(blocks)), t, &
          gf%dormant)
      end if
    end subroutine states_halo
  end subroutine ghost_fluid_fill

  !> The right-hand side of phase p on block blk (number b on this rank) at stage `stage`,
  !> the faces of the trouble cells at first order when the mask is given. A phase with
  !> strength and a surface first takes its composite level set at the stage's start: which
  !> cells are real (for the radial return), which faces join two of them (upwind scalar
  !> flux) and which lie on its surface (transported variables at the real cell's value);
  !> what came in through the domain's sides goes to the conservation fix. Such a phase is
  !> not computed at all on a block it is absent from.
  subroutine phase_rhs(gf, cuts, ls, ph, num, fix, blk, b, p, stage, wall, vwall, work, nf, &
      failed, trouble)
    type(gf_t), intent(inout) :: gf
    type(cut_t), intent(inout), target :: cuts(:)
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(numerics_t), intent(in) :: num
    type(fix_t), intent(inout) :: fix
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: b, p, stage
    logical, intent(in) :: wall(2, 3)
    real(wp), intent(in) :: vwall(2, 3)
    type(euler_work_t), intent(inout) :: work
    integer, intent(inout) :: nf
    logical, intent(inout) :: failed
    logical, intent(in), optional :: trouble(:, :, :)
    real(wp), allocatable :: wet(:, :, :)
    integer :: lo(3), hi(3), e(3), box(2, 3)
    logical :: near(blk%n(1), blk%n(2), blk%n(3))
    integer, allocatable :: boxes(:, :, :)   !< the boxes computed (none: the whole block)
    type(cut_t), pointer :: cut   !< phase p's cut-cell update (null: p is not a cut phase)
    integer :: k
    cut => null()
    do k = 1, size(cuts)
      if (cuts(k)%on .and. cuts(k)%p == p) cut => cuts(k)
    end do
    if (ls%n > 0 .and. (ph%strong(p) .or. associated(cut))) then
      lo = 1 - blk%lay%ng
      hi = blk%n + blk%lay%ng
      call ls_region(ls, p, lo, hi, blk%q(:, :, :, ph%ils + 1:ph%nvar), &
        gf%work%bigphi(:, :, :, p), gf%work%owner(:, :, :, p))
      gf%work%isreal(:, :, :, p) = gf%work%bigphi(:, :, :, p) < 0.0_wp
      ! a phase absent from the block (every cell over two cells beyond its region: none can
      ! turn real in the stage) is not computed, updated or corrected (block_stage,
      ! phase_corrections): its cells take the rest state; the cost follows the phases present.
      ! Where present, only the boxes of its cells within two cells of its region are, one in
      ! each tile of the block (the rest again takes the rest state after the update): a
      ! grain's colour is computed over about its own cells, not its colour's box in the block.
      if (.not. cuts(1)%on) then
        near = gf%work%bigphi(1:blk%n(1), 1:blk%n(2), 1:blk%n(3), p) &
          <= 2.0_wp * maxval(blk%lay%dx(1:blk%lay%ndim))
        if (.not. any(near)) then
          gf%absent(p) = .true.
          if (fix%on) fix%bflux(:, p, b, stage) = 0.0_wp
          gf%counts%absent = gf%counts%absent + 1
          return
        end if
        boxes = near_boxes(near, tile_cells)
      end if
      if (associated(cut)) then
        ! the cut-cell phase: the rate of its content, fluxes times the wet faces; every
        ! face with a wet part joins two wet cells, and there the transported variables
        ! (S, eps_p, w_c) move with the mass flux (upwind), whatever the cells' centres.
        ! A dry cell's faces are dry and its rate 0: only the box of the wet cells and one
        ! cell around them is computed (none where the block has no wet cell)
        allocate(wet(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)))
        wet = gf%work%bigphi(:, :, :, p)
        e = max(blk%lay%ng - 1, 0)
        associate (a => cut%ext(b)%a)
          wet(1-e(1):blk%n(1)+e(1), 1-e(2):blk%n(2)+e(2), 1-e(3):blk%n(3)+e(3)) = &
            merge(-1.0_wp, 1.0_wp, a > 0.0_wp)
        end associate
        ! (the box is kept for the update: m_gfm_cut_box)
        box = box_below(wet(1:blk%n(1), 1:blk%n(2), 1:blk%n(3)))
        cut%rate_box(:, :, b) = box_empty
        if (any(box(1, :) > box(2, :))) then
          blk%rhs(:, :, :, ph%lo(p):ph%hi(p)) = 0.0_wp
          return
        end if
        box(1, :) = max(box(1, :) - 1, 1)
        box(2, :) = min(box(2, :) + 1, blk%n)
        cut%rate_box(:, :, b) = box
        call euler_rhs(blk%lay, ph%eos(p), ph%st(p), num, blk%q(:, :, :, ph%lo(p):ph%hi(p)), &
          blk%rhs(:, :, :, ph%lo(p):ph%hi(p)), blk%offset, wall, vwall, work, nf, failed, &
          wet, trouble, cut%faces(b), reshape(box, [2, 3, 1]))
        cut%side(1:2, stage, b) = cut%side(1:2, stage, b) + work%bflux
        ! with the last cut phase's rate: the contacts between every pair of cut phases
        if (p == cuts(size(cuts))%p) call contacts()
        return
      end if
      ! (with a cut-cell phase in the scene: no boxes, the whole block; an unallocated
      ! actual argument is an absent optional one)
      call euler_rhs(blk%lay, ph%eos(p), ph%st(p), num, blk%q(:, :, :, ph%lo(p):ph%hi(p)), &
        blk%rhs(:, :, :, ph%lo(p):ph%hi(p)), blk%offset, wall, vwall, work, nf, failed, &
        gf%work%bigphi(:, :, :, p), trouble, boxes=boxes)
      if (fix%on) fix%bflux(:, p, b, stage) = work%bflux
    else
      call euler_rhs(blk%lay, ph%eos(p), ph%st(p), num, blk%q(:, :, :, ph%lo(p):ph%hi(p)), &
        blk%rhs(:, :, :, ph%lo(p):ph%hi(p)), blk%offset, wall, vwall, work, nf, failed, &
        trouble=trouble)
    end if

  contains

    !> The interface exchange of every pair of cut phases (m_gfm_cut_contact) in the cells
    !> whose rates both computed.
    subroutine contacts()
      integer :: k1, k2, p1, p2, both(2, 3)
      real(wp) :: given   !< the energy rate the first phase gave the second (times volume)
      do k1 = 1, size(cuts) - 1
        do k2 = k1 + 1, size(cuts)
          both(1, :) = max(cuts(k1)%rate_box(1, :, b), cuts(k2)%rate_box(1, :, b))
          both(2, :) = min(cuts(k1)%rate_box(2, :, b), cuts(k2)%rate_box(2, :, b))
          if (any(both(1, :) > both(2, :))) cycle
          p1 = cuts(k1)%p
          p2 = cuts(k2)%p
          call cut_contact(blk%lay, blk%offset, both, ph%eos(p1), ph%eos(p2), ph%shear(p1), &
            ph%shear(p2), blk%q(:, :, :, ph%lo(p1):ph%hi(p1)), &
            blk%q(:, :, :, ph%lo(p2):ph%hi(p2)), cuts(k1)%faces(b), cuts(k2)%faces(b), &
            blk%rhs(:, :, :, ph%lo(p1):ph%hi(p1)), blk%rhs(:, :, :, ph%lo(p2):ph%hi(p2)), &
            cuts(k1)%contacts, given)
          cuts(k1)%side(3, stage, b) = cuts(k1)%side(3, stage, b) - given
          cuts(k2)%side(3, stage, b) = cuts(k2)%side(3, stage, b) + given
        end do
      end do
    end subroutine contacts
  end subroutine phase_rhs

  !> After the stage update of block blk: the radial return of every phase with strength
  !> (with a surface, on its real cells, a cell that has just turned real brought to the
  !> yield surface without plastic work), overlap between material bodies removed, debris
  !> taken out of the bodies, and the rest state outside each phase's region.
  !> With a cut-cell phase: its content after the update instead (m_gfm_cut); its radial
  !> return and rest states come when the content is made states again.
  subroutine phase_corrections(gf, cut, ls, ph, fix, blk, b, stage, order, dt, thermal)
    type(gf_t), intent(inout) :: gf
    type(cut_t), intent(inout) :: cut(:)
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(fix_t), intent(inout) :: fix
    type(block_t), intent(inout) :: blk
    integer, intent(in) :: b, stage, order
    real(wp), intent(in) :: dt
    logical, intent(in) :: thermal
    logical :: fresh(blk%n(1), blk%n(2), blk%n(3))
    integer :: p, lo(3), hi(3), k
    if (cut(1)%on) then
      do k = 1, size(cut)
        call cut_update(cut(k), b, blk, ph, stage, order, dt)
      end do
      return
    end if
    associate (n => blk%n, w => gf%work)
      lo = 1 - blk%lay%ng
      hi = n + blk%lay%ng
      do p = 1, ph%nphase
        if (.not. ph%strong(p)) cycle
        if (ls%n > 0) then
          ! (a phase absent from the block has no real cell: no radial return)
          if (gf%absent(p)) cycle
          ! the region after the update: its cells that were not real at the start are fresh
          call ls_region(ls, p, lo, hi, blk%q(:, :, :, ph%ils + 1:ph%nvar), &
            w%bigphi(:, :, :, p), w%owner(:, :, :, p))
          fresh = w%bigphi(1:n(1), 1:n(2), 1:n(3), p) < 0.0_wp .and. &
            .not. w%isreal(1:n(1), 1:n(2), 1:n(3), p)
          w%isreal(:, :, :, p) = w%bigphi(:, :, :, p) < 0.0_wp
          call plastic_correction(blk%lay, ph%eos(p), ph%st(p), thermal, dt, &
            blk%q(:, :, :, ph%lo(p):ph%hi(p)), w%isreal(1:n(1), 1:n(2), 1:n(3), p), fresh)
        else
          call plastic_correction(blk%lay, ph%eos(p), ph%st(p), thermal, dt, &
            blk%q(:, :, :, ph%lo(p):ph%hi(p)))
        end if
      end do
      if (count(ls%kind == ls_material) > 1) call ls_separate(ls, &
        blk%q(1:n(1), 1:n(2), 1:n(3), ph%ils + 1:ph%nvar))
      if (any(ls%kind == ls_material)) call gfm_drop_debris(blk%lay, gf%scn, ls, &
        blk%offset, blk%q, gf%counts, fix%lost)
      if (ls%n > 0) call gfm_rest(blk%lay, gf%scn, ls, blk%q, gf%work, gf%absent)
      if (ls%n > 0) gf%rested(b) = .true.
    end associate
  end subroutine phase_corrections

  !> The cut-cell phase's content and states (m_gfm_cut; nothing to do without one), on
  !> every awake block, by mode:
  !> - states_geometry (the first stage): its geometry from the level sets;
  !> - states_open (a later stage, after the halo exchange): also its content made states
  !>   (the emptied cells' content to their neighbours, the halo exchanged again when some
  !>   content moved, the small cells mixed: cut_donate, cut_open) and their radial return;
  !> - states_end (after the last stage of a step): every halo first brought up to date,
  !>   then as states_open, the content kept for the next step (c0), the fractions, the rest
  !>   state beyond the phase and the step's in-flow through the sides in the budget; failed
  !>   is then collective;
  !> - states_start (the run's start: the initial state painted or read from a checkpoint):
  !>   every halo brought up to date, the content taken from the states and the fractions.
  !> failed: a state that is not admissible.
  subroutine phase_states(gf, cuts, ls, ph, plan, lay, bc, blocks, t, dt, order, thermal, mode, &
      failed)
    type(gf_t), intent(inout) :: gf
    type(cut_t), intent(inout), target :: cuts(:)   !< one for each cut phase
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: t, dt
    integer, intent(in) :: order, mode
    logical, intent(in) :: thermal
    logical, intent(inout) :: failed
    logical :: states, final, bad, open_sides(2, 3)
    logical :: moved(size(blocks))   !< a block whose content some cell gave or took
    integer :: mbox(2, 3, size(blocks))   !< the box of its cells that did (m_gfm_cut_box)
    logical, allocatable :: isreal(:, :, :), fresh(:, :, :), touch(:, :, :)
    real(wp), allocatable :: share(:, :, :)   !< content over state: the wet part
    real(wp), allocatable :: step(:, :)       !< this step's budget terms per block
    real(wp) :: w(3)                          !< the stages' weights
    real(wp) :: total(8)
    integer :: b, p, m, lo(3), hi(3), n(3), v0, box(2, 3), k, kbox(2, 3), k2
    logical :: body_moved, followed   !< a material body's level set moved (cut_follow_body)
    logical :: kmoved
    if (.not. cuts(1)%on) return
    body_moved = .false.
    if (mode == states_start) call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_all, t, &
      gf%dormant)
    if (mode == states_end) call end_halo()
    do k = 1, size(cuts)
      if (mode == states_start) cuts(k)%started = .false.
    end do
    open_sides = reshape([bc%lo == bc_outflow, bc%hi == bc_outflow], [2, 3], order=[2, 1])
    states = mode == states_open .or. mode == states_end
    final = mode == states_end
    bad = .false.
    moved = .false.
    mbox = spread(box_empty, 3, size(blocks))
    do k = 1, size(cuts)
      associate (cut => cuts(k))
        p = cut%p
        v0 = ph%lo(p) - 1
        do b = 1, size(blocks)
          if (gf%dormant(b)) cycle
          ! (a step's first stage: the geometry of the last step's end, when nothing has moved
          ! the level sets since)
          if (mode == states_geometry .and. cut%kept(b)) cycle
          associate (blk => blocks(b), w => gf%work, f => cut%faces(b))
            call phase_region(blk)
            call cut_geometry(cut, b, blk, w%bigphi(:, :, :, p), open_sides, cut%ext(b)%a)
            if (.not. allocated(cut%ext_n(b)%a)) then
              ! a block that has just woken: it held none of the phase at the last step's end
              allocate(cut%ext_n(b)%a, mold=cut%ext(b)%a)
              cut%ext_n(b)%a = 0.0_wp
            end if
            if (.not. cut%started .and. .not. cut%restored) then
              ! the run's start: a wet cell whose centre lies outside holds no state of the
              ! phase yet; its ghost state (the phase's state beside it) makes its content
              call gfm_fill(blk%lay, gf%scn, ls, blk%q, gf%work, gf%counts, gf%dormant(b), &
                .false.)
              do m = 1, ph%nflow
                cut%c0(1:n(1), 1:n(2), 1:n(3), m, b) = &
                  f%alpha * blk%q(1:n(1), 1:n(2), 1:n(3), v0 + m)
              end do
            end if
            if (.not. cut%started) then
              if (cut%restored_fractions) then
                ! a restart's fractions came from the checkpoint (those of the level set before
                ! the step end's follow); beyond the domain's sides the level set's
                where (cut%ext_n(b)%a < 0.0_wp) cut%ext_n(b)%a = cut%ext(b)%a
              else
                cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b) = f%alpha
                cut%ext_n(b)%a = cut%ext(b)%a
              end if
            end if
            if (states) then
              ! the cells content can reach: the content's box and those that may be wet
              box = box_whole(n)
              if (cut%boxed(b)) box = box_union(cut%box(:, :, b), cut%wet_box(:, :, b))
              cut%box(:, :, b) = box
              call cut_donate(blk, ph, p, cut%ext(b)%a, cut%ext_n(b)%a, box, kmoved, kbox)
              moved(b) = moved(b) .or. kmoved
              mbox(:, :, b) = box_union(mbox(:, :, b), kbox)
            end if
          end associate
        end do
        cut%started = .true.
        cut%kept = .false.
      end associate
    end do
    if (.not. states) return
    call content_halo()
    do k = 1, size(cuts)
      associate (cut => cuts(k))
        p = cut%p
        v0 = ph%lo(p) - 1
        do b = 1, size(blocks)
          if (gf%dormant(b)) then
            ! dry: its step-start states (a block that fell dormant in this step held content,
            ! which the budget counts as stranded)
            n = blocks(b)%n
            blocks(b)%q(1:n(1), 1:n(2), 1:n(3), ph%lo(p):ph%hi(p)) = &
              blocks(b)%q0(:, :, :, ph%lo(p):ph%hi(p))
            cut%put_box(:, :, b) = box_whole(n)
            cut%boxed(b) = .false.
            if (final) call cut_strand(cut, b, blocks(b))
            if (final) cut%c0(1:n(1), 1:n(2), 1:n(3), :, b) = 0.0_wp
            if (final .and. allocated(cut%ext_n(b)%a)) cut%ext_n(b)%a = 0.0_wp
            if (final) cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b) = 0.0_wp
            cycle
          end if
          associate (blk => blocks(b), w => gf%work, f => cut%faces(b))
            call phase_region(blk)
            touch = f%alpha < 0.0_wp   ! (all false, shaped as the block)
            do k2 = 1, size(cuts)
              if (k2 /= k) touch = touch .or. cuts(k2)%faces(b)%alpha > 0.0_wp
            end do
            call cut_open(cut, b, blk, ph, cut%ext(b)%a, open_sides, final, bad, &
              w%bigphi(:, :, :, p), w%owner(:, :, :, p), cut%box(:, :, b), gf%scn%band, touch)
            if (ph%strong(p)) then
              isreal = w%bigphi(1:n(1), 1:n(2), 1:n(3), p) < 0.0_wp
              fresh = isreal .and. .not. cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b) > 0.0_wp
              call plastic_correction(blk%lay, ph%eos(p), ph%st(p), thermal, dt, &
                blk%q(:, :, :, ph%lo(p):ph%hi(p)), isreal, fresh)
              ! the returned stress, eps_p and w_c back into content, per mass (a cut cell's
              ! state has the density of the material beside it, m_gfm_cut); beyond the box the
              ! content is zero and stays so (m_gfm_cut_box)
              box = cut%box(:, :, b)
              if (all(box(1, :) <= box(2, :))) then
                associate (x => box(:, 1), y => box(:, 2), z => box(:, 3))
                  share = f%alpha(x(1):x(2), y(1):y(2), z(1):z(2))
                  where (blk%q(x(1):x(2), y(1):y(2), z(1):z(2), v0 + i_rho) > 0.0_wp) share = &
                    cut%c(x(1):x(2), y(1):y(2), z(1):z(2), i_rho, b) &
                    / blk%q(x(1):x(2), y(1):y(2), z(1):z(2), v0 + i_rho)
                  do m = n_euler + 1, ph%nflow
                    cut%c(x(1):x(2), y(1):y(2), z(1):z(2), m, b) = &
                      share * blk%q(x(1):x(2), y(1):y(2), z(1):z(2), v0 + m)
                  end do
                end associate
              end if
            end if
            if (final) then
              ! (beyond the box both are zero already)
              box = cut%box(:, :, b)
              if (all(box(1, :) <= box(2, :))) then
                associate (x => box(:, 1), y => box(:, 2), z => box(:, 3))
                  cut%c0(x(1):x(2), y(1):y(2), z(1):z(2), :, b) = &
                    cut%c(x(1):x(2), y(1):y(2), z(1):z(2), :, b)
                end associate
              end if
              cut%alpha_n(1:n(1), 1:n(2), 1:n(3), b) = f%alpha
              cut%ext_n(b)%a = cut%ext(b)%a
              ! (before the rest state replaces the states of the cells whose centre is outside)
              call cut_follow(blk, ph%ils, ph%lo(cut%p) - 1, ls, f%alpha, &
                cut%c(:, :, :, i_rho, b), cut%follow)
              if (cut%body_dead > 0.0_wp) call cut_follow_body(blk, ph%ils, ph%lo(cut%p) - 1, &
                ls, cut%p, f%alpha, cut%c(:, :, :, i_rho, b), cut%body_dead, followed)
              body_moved = body_moved .or. followed
            end if
          end associate
        end do
      end associate
    end do
    ! the rest state beyond every phase (after every cut phase's content is states); with
    ! contacts, first the bodies' level sets moved apart where they overlap (m_levelset_bodies'
    ! ls_separate, to their mid-surface): the contents stay, only the surfaces move, and the
    ! next step makes the geometry again
    do b = 1, size(blocks)
      if (gf%dormant(b) .or. .not. final) cycle
      associate (blk => blocks(b))
        if (size(cuts) > 1) then
          call ls_separate(ls, blk%q(1:blk%n(1), 1:blk%n(2), 1:blk%n(3), ph%ils + 1:ph%nvar))
          body_moved = .true.
        end if
        call gf_fit(gf, blk%lay, ph%nflow, ph%nphase)
        call gfm_rest(blk%lay, gf%scn, ls, blk%q, gf%work)
      end associate
    end do
    if (.not. final) then
      failed = failed .or. bad
      return
    end if
    failed = comm_any(bad)
    if (failed) return
    ! the geometry holds for the next step's first stage where nothing moves the level sets
    ! before it: a void's level set follows its content at every step (cut_follow)
    ! and a material body's follows it where they drift apart (cut_follow_body)
    body_moved = comm_any(body_moved)
    ! what came in through the domain's sides in this step (the stages' weights) and what
    ! the cell rules sent out or stranded, summed over the blocks in the order of their ids
    allocate(step(8, size(blocks)))
    w = rk_weights(order)
    do k = 1, size(cuts)
      associate (cut => cuts(k))
        cut%kept = .not. gf%dormant .and. .not. any(ls%kind == ls_void) .and. .not. body_moved
        do b = 1, size(blocks)
          step(1:3, b) = dt * (cut%side(:, 1, b) * w(1) + cut%side(:, 2, b) * w(2) &
            + cut%side(:, 3, b) * w(3))
          step(1:2, b) = step(1:2, b) + cut%out(1:2, b)
          step(8, b) = step(3, b)
          step(3:7, b) = cut%out(3:7, b)
        end do
        total = comm_sum_by_key(step, [(blocks(b)%id, b = 1, size(blocks))], lay%nblocks)
        cut%crossed = cut%crossed + total(1:2)
        cut%stranded = cut%stranded + total(3:4)
        cut%closing = cut%closing + total(5:6)
        cut%held = cut%held + total(7)
        cut%exchanged = cut%exchanged + total(8)
      end associate
    end do

  contains

    !> The content the cells gave and took into the halo. Every other block's halo already
    !> holds the content as it is (the exchange before this pass, the sides' conditions
    !> from the same interior): where none moved on any rank, nothing is exchanged; on one
    !> rank, only the cells that changed are copied again, and the side conditions made
    !> again where they could read them (m_boundary's refresh_ghosts, which gives what the
    !> whole exchange gives).
    subroutine content_halo()
      if (.not. comm_any(any(moved))) return
      if (comm_any(any(plan%remote))) then
        call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_flow, t, gf%dormant)
        return
      end if
      call refresh_ghosts(plan, lay, bc, blocks, ph, mbox, t, gf%dormant)
    end subroutine content_halo

    !> Every halo brought up to date after the step's last stage: the level sets', which
    !> moved everywhere, and the content's, which that stage's update wrote only near
    !> each block's boxes (m_gfm_cut's near_box; since the flow exchange after the stage's
    !> ghost fill nothing else wrote them): on one rank only there (m_boundary's
    !> refresh_ghosts), otherwise the whole exchange.
    subroutine end_halo()
      integer :: near(2, 3, size(blocks)), c
      if (comm_any(any(plan%remote))) then
        call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_all, t, gf%dormant)
        return
      end if
      call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_level_sets, t, gf%dormant)
      do c = 1, size(blocks)
        near(:, :, c) = box_empty
        if (gf%dormant(c)) cycle
        do k = 1, size(cuts)
          near(:, :, c) = box_union(near(:, :, c), cut_near(cuts(k), c, blocks(c)%n))
        end do
      end do
      call refresh_ghosts(plan, lay, bc, blocks, ph, near, t, gf%dormant)
    end subroutine end_halo

    !> Block blk's extent (n its cells, lo:hi with the halo), the work arrays fitted to it,
    !> and the phase's composite level set and owners over it: what both passes over the
    !> blocks start from.
    subroutine phase_region(blk)
      type(block_t), intent(in) :: blk
      n = blk%n
      lo = 1 - blk%lay%ng
      hi = n + blk%lay%ng
      call gf_fit(gf, blk%lay, ph%nflow, ph%nphase)
      call ls_region(ls, p, lo, hi, blk%q(:, :, :, ph%ils + 1:ph%nvar), &
        gf%work%bigphi(:, :, :, p), gf%work%owner(:, :, :, p))
    end subroutine phase_region

  end subroutine phase_states

end module m_gfm_stage
