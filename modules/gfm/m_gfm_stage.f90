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
  use m_boundary, only: bc_kind_t, fill_ghosts, ghosts_flow
  use m_phases, only: phases_t
  use m_config, only: body_t
  use m_euler, only: numerics_t, euler_work_t, euler_rhs
  use m_elastoplastic, only: plastic_correction
  use m_levelset_bodies, only: ls_set_t, ls_region, ls_separate, ls_material
  use m_scene, only: rigid_bodies_move
  use m_gfm, only: gf_t, gf_fit, gfm_fill, gfm_rest, gfm_drop_debris, gfm_dormant
  use m_gfm_conserve, only: fix_t
  implicit none
  private
  public :: ghost_fluid_fill, phase_rhs, phase_corrections

contains

  !> The ghost-fluid stage at time t (DESIGN section 5): rigid level sets moved to t, ghost
  !> bands filled on every block (m_gfm). The caller then fills the flow ghosts again
  !> (m_boundary's fill_ghosts, dormant blocks skipped) so that each block sees its
  !> neighbours' ghosts. A dormant block (every cell, halo included, beyond every band) is not
  !> computed, and its flow halo is not kept. Before any fill, a block that was dormant and
  !> wakes (its level sets, always exchanged, now reach into a band) takes the flow halo it
  !> missed, from neighbours not yet filled: the result is that of exchanging every halo
  !> every time.
  subroutine ghost_fluid_fill(gf, ls, ph, plan, lay, bc, bodies, blocks, t)
    type(gf_t), intent(inout) :: gf
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(body_t), intent(in) :: bodies(:)
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: t
    integer :: b
    call rigid_bodies_move(lay, bodies, ls, ph%ils, blocks, t)
    do b = 1, size(blocks)
      if (.not. gf%dormant(b)) cycle
      call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
      if (gfm_dormant(blocks(b)%lay, gf%scn, ls, blocks(b)%q, gf%work)) cycle
      call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_flow, t, only=b)
    end do
    do b = 1, size(blocks)
      call gf_fit(gf, blocks(b)%lay, ph%nflow, ph%nphase)
      call gfm_fill(blocks(b)%lay, gf%scn, ls, blocks(b)%q, gf%work, gf%counts, gf%dormant(b))
    end do
  end subroutine ghost_fluid_fill

  !> The right-hand side of phase p on block blk (number b on this rank) at stage `stage`,
  !> the faces of the trouble cells at first order when the mask is given. A phase with
  !> strength and a surface first takes its composite level set at the stage's start: which
  !> cells are real (for the radial return), which faces join two of them (upwind scalar
  !> flux) and which lie on its surface (transported variables at the real cell's value);
  !> what came in through the domain's sides goes to the conservation fix.
  subroutine phase_rhs(gf, ls, ph, num, fix, blk, b, p, stage, wall, vwall, work, nf, failed, &
      trouble)
    type(gf_t), intent(inout) :: gf
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
    integer :: lo(3), hi(3)
    if (ls%n > 0 .and. ph%strong(p)) then
      lo = 1 - blk%lay%ng
      hi = blk%n + blk%lay%ng
      call ls_region(ls, p, lo, hi, blk%q(:, :, :, ph%ils + 1:ph%nvar), &
        gf%work%bigphi(:, :, :, p), gf%work%owner(:, :, :, p))
      gf%work%isreal(:, :, :, p) = gf%work%bigphi(:, :, :, p) < 0.0_wp
      call euler_rhs(blk%lay, ph%eos(p), ph%st(p), num, blk%q(:, :, :, ph%lo(p):ph%hi(p)), &
        blk%rhs(:, :, :, ph%lo(p):ph%hi(p)), blk%offset, wall, vwall, work, nf, failed, &
        gf%work%bigphi(:, :, :, p), trouble)
      if (fix%on) fix%bflux(:, p, b, stage) = work%bflux
    else
      call euler_rhs(blk%lay, ph%eos(p), ph%st(p), num, blk%q(:, :, :, ph%lo(p):ph%hi(p)), &
        blk%rhs(:, :, :, ph%lo(p):ph%hi(p)), blk%offset, wall, vwall, work, nf, failed, &
        trouble=trouble)
    end if
  end subroutine phase_rhs

  !> After the stage update of block blk: the radial return of every phase with strength
  !> (with a surface, on its real cells, a cell that has just turned real brought to the
  !> yield surface without plastic work), overlap between material bodies removed, debris
  !> taken out of the bodies, and the rest state outside each phase's region.
  subroutine phase_corrections(gf, ls, ph, fix, blk, dt, thermal)
    type(gf_t), intent(inout) :: gf
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(fix_t), intent(inout) :: fix
    type(block_t), intent(inout) :: blk
    real(wp), intent(in) :: dt
    logical, intent(in) :: thermal
    logical :: fresh(blk%n(1), blk%n(2), blk%n(3))
    integer :: p, lo(3), hi(3)
    associate (n => blk%n, w => gf%work)
      lo = 1 - blk%lay%ng
      hi = n + blk%lay%ng
      do p = 1, ph%nphase
        if (.not. ph%strong(p)) cycle
        if (ls%n > 0) then
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
      if (ls%n > 0) call gfm_rest(blk%lay, gf%scn, ls, blk%q, gf%work)
    end associate
  end subroutine phase_corrections

end module m_gfm_stage
