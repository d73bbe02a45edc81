!> The heat effects of the phases, once per step after the Runge-Kutta stages (operator
!> splitting, first order in time; manual/reaction.md section 3): heat conduction within each
!> conducting phase's real cells (m_conduction) and the reaction of each reacting phase's
!> real cells (m_reaction), both at the temperatures the step left, so that neither sees the
!> other's change within the step. Real cells are those inside the phase's region (the
!> composite level set < 0, m_levelset_bodies); without level sets every cell. The reaction
!> heat is energy the conservation fix must not take back: it is counted as a gain in the
!> fix's per-step loss (m_gfm_conserve's lost). Called only when the deck has one of the two
!> effects, so a run without them does exactly what it did before.
module m_phase_heat
  use m_kinds, only: wp
  use m_layout, only: layout_t, cell_volume
  use m_blocks, only: block_t
  use m_halo, only: halo_plan_t
  use m_boundary, only: bc_kind_t, fill_ghosts, ghosts_all
  use m_phases, only: phases_t
  use m_levelset_bodies, only: ls_set_t, ls_region
  use m_gfm, only: gf_t, gf_fit
  use m_gfm_conserve, only: fix_t
  use m_eos, only: eos_temperature
  use m_elastoplastic, only: primitive_row, solid_temperature
  use m_conduction, only: conduct_block
  use m_reaction, only: reaction_row, reaction_none
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en
  implicit none
  private
  public :: phase_heat

contains

  !> Conduction and reaction over dt on every awake block of this rank, at time t (the
  !> step's end). Conduction needs the neighbours' temperatures: the halos are filled first.
  subroutine phase_heat(gf, ls, ph, fix, plan, lay, bc, blocks, t, dt)
    type(gf_t), intent(inout) :: gf
    type(ls_set_t), intent(in) :: ls
    type(phases_t), intent(in) :: ph
    type(fix_t), intent(inout) :: fix
    type(halo_plan_t), intent(inout) :: plan
    type(layout_t), intent(in) :: lay
    type(bc_kind_t), intent(in) :: bc
    type(block_t), intent(inout) :: blocks(:)
    real(wp), intent(in) :: t, dt
    real(wp), allocatable :: temp(:, :, :), en0(:)
    logical, allocatable :: isreal(:, :, :)
    integer :: b, p, lo(3), hi(3), j, k, i, off, n
    if (ph%has_conduction) call fill_ghosts(plan, lay, bc, blocks, ph, ghosts_all, t, &
      gf%dormant)
    do b = 1, size(blocks)
      if (gf%dormant(b)) cycle
      associate (blk => blocks(b))
        lo = 1 - blk%lay%ng
        hi = blk%n + blk%lay%ng
        n = blk%n(1)
        if (allocated(temp)) then
          if (any(shape(temp) /= hi - lo + 1)) deallocate(temp, isreal, en0)
        end if
        if (.not. allocated(temp)) allocate(temp(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), &
          isreal(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3)), en0(n))
        do p = 1, ph%nphase
          if (.not. ph%conductivity(p) > 0.0_wp .and. ph%rt(p)%model == reaction_none) cycle
          off = ph%lo(p) - 1
          isreal = .true.
          if (ls%n > 0) then
            call gf_fit(gf, blk%lay, ph%nflow, ph%nphase)
            call ls_region(ls, p, lo, hi, blk%q(:, :, :, ph%ils + 1:ph%nvar), &
              gf%work%bigphi(:, :, :, p), gf%work%owner(:, :, :, p))
            isreal = gf%work%bigphi(:, :, :, p) < 0.0_wp
          end if
          call phase_temperature(ph, p, blk%q, lo, hi, temp)
          if (ph%conductivity(p) > 0.0_wp) call conduct_block(blk%lay, blk%offset, &
            ph%conductivity(p), dt, temp, isreal, blk%q(:, :, :, off + i_en))
          if (ph%rt(p)%model == reaction_none) cycle
          do k = 1, blk%n(3)
            do j = 1, blk%n(2)
              en0 = blk%q(1:n, j, k, off + i_en)
              call reaction_row(ph%rt(p), n, dt, temp(1:n, j, k), blk%q(1:n, j, k, off + i_rho), &
                blk%q(1:n, j, k, off + ph%i_lambda), blk%q(1:n, j, k, off + i_en), &
                isreal(1:n, j, k))
              ! the heat released is a gain the conservation fix must keep
              if (.not. fix%on) cycle
              do i = 1, n
                fix%lost(2, p) = fix%lost(2, p) - (blk%q(i, j, k, off + i_en) - en0(i)) &
                  * cell_volume(blk%lay, blk%offset, i)
              end do
            end do
          end do
        end do
      end associate
    end do
  end subroutine phase_heat

  !> The temperature of phase p over the padded block (the solid's less its elastic and
  !> stored energy, as the plot's T).
  subroutine phase_temperature(ph, p, q, lo, hi, temp)
    type(phases_t), intent(in) :: ph
    integer, intent(in) :: p, lo(3), hi(3)
    real(wp), intent(in) :: q(lo(1):, lo(2):, lo(3):, :)
    real(wp), intent(out) :: temp(lo(1):, lo(2):, lo(3):)
    real(wp), dimension(hi(1) - lo(1) + 1) :: rho, u, v, w, pr, e
    integer :: j, k, off, nr
    off = ph%lo(p) - 1
    nr = hi(1) - lo(1) + 1
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        call primitive_row(ph%eos(p), nr, q(:, j, k, off + i_rho), q(:, j, k, off + i_mx), &
          q(:, j, k, off + i_my), q(:, j, k, off + i_mz), q(:, j, k, off + i_en), rho, u, v, &
          w, pr, e)
        if (ph%strong(p)) then
          call solid_temperature(ph%eos(p), ph%st(p), nr, rho, e, &
            q(:, j, k, off + 1:off + ph%nflow), temp(:, j, k))
        else
          call eos_temperature(ph%eos(p), nr, rho, e, temp(:, j, k))
        end if
      end do
    end do
  end subroutine phase_temperature

end module m_phase_heat
