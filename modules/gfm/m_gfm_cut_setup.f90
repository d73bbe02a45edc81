!> Whether the cut-cell update (m_gfm_cut) applies to a scene and, where it does, one cut_t
!> for each cut phase with its arrays sized for this rank's blocks (issue 15, manual/theory.md
!> sections 7b and 7e, interfaces.md 2c-2d).
module m_gfm_cut_setup
  use m_kinds, only: wp
  use m_layout, only: layout_t
  use m_blocks, only: block_t
  use m_phases, only: phases_t
  use m_levelset_bodies, only: ls_set_t, ls_material, ls_void
  use m_gfm_cut, only: cut_t, cut_boxes
  use m_config, only: is_set
  implicit none
  private
  public :: cut_setup

  !> a body's level set follows its content beyond this drift (cells) where bodies touch on
  !> cut cells and the deck leaves &numerics body_follow unset (interfaces.md 2d: the
  !> ricochet's level set within 1-2 % of its content to 80 us, 36 % apart without)
  real(wp), parameter :: contact_follow = 0.05_wp

contains

  !> Whether the cut-cell update applies to a scene: the deck's &numerics conserve (cfg_mode,
  !> 'cut_cell', or 'auto' unless the scene has heat conduction or reaction, whose sources a
  !> cut cell's content does not take: `sources`), level sets, one phase, every surface of it
  !> free; under 'auto' also not a void body with a material body (a hole carved in a solid:
  !> only a void in the base material follows its content, so a hole's surface drifts from
  !> it and its trailing point gives pressure spikes, interfaces.md 2c). reason: why
  !> (run.log's `gfm: cut-cell update` line).
  pure subroutine cut_applies(cfg_mode, sources, ph, ls, on, reason)
    character(len=*), intent(in) :: cfg_mode
    logical, intent(in) :: sources
    type(phases_t), intent(in) :: ph
    type(ls_set_t), intent(in) :: ls
    logical, intent(out) :: on
    character(len=*), intent(out) :: reason
    on = .false.
    if (cfg_mode /= 'cut_cell' .and. cfg_mode /= 'auto') then
      reason = "off: &numerics conserve = '" // trim(cfg_mode) // "'"
    else if (ls%n == 0) then
      reason = 'off: no level sets'
    else if (ph%nphase > 1 .and. cfg_mode == 'cut_cell' .and. all(ls%kind == ls_material)) then
      ! material bodies in contact (MMI), every phase a cut phase: asked for explicitly
      ! while it is being verified (m_gfm_cut_contact; not yet the default)
      if (sources) then
        reason = 'off: not built with heat conduction or reaction'
      else
        on = .true.
        reason = 'on: every phase (' // trim(ph%material(1)) // ', ...) with free surfaces ' &
          // 'and contacts (conserve = ''cut_cell'')'
      end if
      return
    else if (ph%nphase /= 1 .or. any(ls%kind /= ls_material .and. ls%kind /= ls_void)) then
      reason = 'off: built for one phase with free surfaces only (contacts only with ' &
        // 'conserve = ''cut_cell'', no rigid body yet); the conservation fix instead'
    else if (sources) then
      ! (an explicit 'cut_cell' with these is refused by the deck check)
      reason = 'off: not built with heat conduction or reaction (their sources do not ' &
        // 'reach the cut cells'' content); the conservation fix instead'
    else if (cfg_mode == 'auto' .and. any(ls%kind == ls_material) .and. &
        any(ls%kind == ls_void)) then
      reason = "off: conserve = 'auto' and a void body with a material body (a hole's " &
        // "surface is not made to follow its content: pressure spikes, interfaces.md 2c); " &
        // "the conservation fix instead (conserve = 'cut_cell' asks for it)"
    else
      on = .true.
      reason = 'on: ' // trim(ph%material(1)) // ' with free surfaces'
      if (cfg_mode == 'auto') reason = trim(reason) // " (conserve = 'auto')"
    end if
  end subroutine cut_applies

  !> Set the cut-cell update up when it applies (cut_applies): cuts(k), one for each cut
  !> phase, with its arrays sized for the blocks of this rank. Without it cuts(1) alone, off,
  !> with the reason; cuts(1)%on says whether the update is on (every cut phase's `on`).
  !> body_dead: &numerics body_follow (cut_t's body_dead; unset: contact_follow where there
  !> are contacts, several cut phases, else 0).
  subroutine cut_setup(cuts, cfg_mode, sources, body_dead, lay, ph, ls, blocks)
    type(cut_t), allocatable, intent(inout) :: cuts(:)
    character(len=*), intent(in) :: cfg_mode   !< &numerics conserve
    logical, intent(in) :: sources             !< heat conduction or reaction in the scene
    real(wp), intent(in) :: body_dead
    type(layout_t), intent(in) :: lay
    type(phases_t), intent(in) :: ph
    type(ls_set_t), intent(inout) :: ls   !< (its mid_contacts set here)
    type(block_t), intent(in) :: blocks(:)
    integer :: k
    logical :: on
    character(len=256) :: reason
    call cut_applies(cfg_mode, sources, ph, ls, on, reason)
    if (allocated(cuts)) deallocate(cuts)
    allocate(cuts(merge(ph%nphase, 1, on)))
    do k = 1, size(cuts)
      cuts(k)%on = on
      cuts(k)%reason = reason
      cuts(k)%body_dead = body_dead
      ! (unset: bodies that touch on cut cells follow their content, interfaces.md 2d; a
      ! body alone in void does not, which would lengthen the Taylor bar, 2c)
      if (.not. is_set(body_dead)) cuts(k)%body_dead = merge(contact_follow, 0.0_wp, &
        size(cuts) > 1)
      if (on) call cut_phase_setup(cuts(k), k, lay, ph, blocks)
    end do
    ! contacts between cut phases meet at one surface (m_levelset_bodies' ls_region)
    ls%mid_contacts = size(cuts) > 1
  end subroutine cut_setup

  !> The arrays of cut phase p, sized for the blocks of this rank.
  subroutine cut_phase_setup(cut, p, lay, ph, blocks)
    type(cut_t), intent(inout) :: cut
    integer, intent(in) :: p
    type(layout_t), intent(in) :: lay
    type(phases_t), intent(in) :: ph
    type(block_t), intent(in) :: blocks(:)
    integer :: n(3), b, g1(3)
    cut%p = p
    n = lay%nmax
    allocate(cut%c(n(1), n(2), n(3), ph%nflow, size(blocks)))
    allocate(cut%c0, mold=cut%c)
    allocate(cut%alpha_n(n(1), n(2), n(3), size(blocks)), cut%faces(size(blocks)))
    allocate(cut%ext(size(blocks)), cut%ext_n(size(blocks)))
    call cut_boxes(cut, size(blocks))
    cut%c = 0.0_wp
    cut%c0 = 0.0_wp
    cut%alpha_n = 0.0_wp
    do b = 1, size(blocks)
      n = blocks(b)%n
      allocate(cut%faces(b)%ax(0:n(1), n(2), n(3)), cut%faces(b)%ay(n(1), 0:n(2), n(3)), &
        cut%faces(b)%az(n(1), n(2), 0:n(3)), cut%faces(b)%alpha(n(1), n(2), n(3)), &
        cut%faces(b)%plane(n(1), n(2), n(3)))
      g1 = merge(1, 0, lay%ng > 0)
      allocate(cut%faces(b)%partial(1-g1(1):n(1)+g1(1), 1-g1(2):n(2)+g1(2), 1-g1(3):n(3)+g1(3)))
    end do
  end subroutine cut_phase_setup

end module m_gfm_cut_setup
