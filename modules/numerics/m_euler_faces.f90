!> The face states and fluxes of a bundle of pencils, for m_euler's right-hand side: the
!> reconstruction, the admissibility test with its fall-back to the cell values, the walls'
!> mirror states, and the flux (manual/theory.md sections 2 and 5.1); and the scheme choices
!> they take (numerics_t). Kernels only.
module m_euler_faces
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_sound_speed2
  use m_characteristic, only: characteristic_work_t, reconstruct_pencils
  use m_flux, only: face_flux, flux_llf_solid
  use m_state, only: n_euler, i_epsp
  implicit none
  private
  public :: numerics_t, faces_and_fluxes

  !> The scheme choices of the right-hand side (m_numerics_defaults resolves the deck's)
  type :: numerics_t
    integer :: scheme = 3                 !< reconstruction (m_reconstruct)
    integer :: variables = 1              !< reconstructed variables (m_characteristic)
    integer :: flux = 1                   !< face flux (m_flux)
    integer :: scalar_flux = 1            !< flux of rho eps_p, rho w_c (m_flux)
    !> surface faces keep the LLF flux of S, eps_p and w_c (&numerics surface_flux = 'llf')
    logical :: surface_llf = .false.
  end type numerics_t

contains

  !> Face states and fluxes of a bundle of nb pencils of n cells: reconstruct, test
  !> admissibility (falling back to the cell values where a face state has rho <= 0 or
  !> c^2 <= 0), then the flux. The EOS and the flux see the nb (n + 1) faces as one list.
  subroutine faces_and_fluxes(eos, shear, num, nb, n, g, nv, ns, wall, vwall, up, surf, pw, &
      wl, wr, el, er, cl, cr, f, chw, nfallback, failed, low, low_bounded)
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: shear
    type(numerics_t), intent(in) :: num
    !> nv variables: ns of the Euler (5) or solid (13) equations, then rho lambda if nv > ns
    integer, intent(in) :: nb, n, g, nv, ns
    logical, intent(in) :: wall(2)
    !> (up and surf are read only with variables beyond the Euler ones, nv > 5)
    logical, intent(in) :: up(nb, 0:n)    !< faces whose scalars take the upwind flux
    integer, intent(in) :: surf(nb, 0:n)  !< faces on a body's surface (m_flux)
    real(wp), intent(in) :: vwall(2)
    real(wp), intent(in) :: pw(nb, 1-g:n+g, nv)
    real(wp), intent(out) :: wl(nb, 0:n, nv), wr(nb, 0:n, nv), el(nb, 0:n), er(nb, 0:n)
    real(wp), intent(out) :: cl(nb, 0:n), cr(nb, 0:n), f(nb, 0:n, nv)
    type(characteristic_work_t), intent(inout) :: chw
    integer, intent(inout) :: nfallback
    logical, intent(inout) :: failed
    !> faces reconstructed at first order (those of the trouble cells; none when absent)
    logical, intent(in), optional :: low(nb, 0:n)
    !> faces whose eps_p and w_c take the cells' values (beside a cut cell, m_gfm_cut)
    logical, intent(in), optional :: low_bounded(nb, 0:n)
    integer :: i, b, nf
    nf = nb * (n + 1)
    ! eps_p, w_c and lambda (pencil places i_epsp .. nv, or lambda alone after a gas) keep face
    ! values within their neighbours' range, so that their upwind transport stays within it
    ! (m_reconstruct's bound_faces)
    call reconstruct_pencils(num%scheme, num%variables, eos, ns > n_euler, shear, nb, n, g, nv, &
      pw, wl, wr, min(i_epsp, ns + 1), chw)
    if (present(low)) then
      do i = 0, n
        do b = 1, nb
          if (.not. low(b, i)) cycle
          wl(b, i, :) = pw(b, i, :)
          wr(b, i, :) = pw(b, i + 1, :)
        end do
      end do
    end if
    if (present(low_bounded)) then
      do i = 0, n
        do b = 1, nb
          if (.not. low_bounded(b, i)) cycle
          wl(b, i, i_epsp:nv) = pw(b, i, i_epsp:nv)
          wr(b, i, i_epsp:nv) = pw(b, i + 1, i_epsp:nv)
        end do
      end do
    end if
    ! a reflecting side: the outer face state is the mirror of the inner one (normal
    ! velocity 2 V - u, shear tractions reversed), so the mass and energy fluxes are
    ! exactly those of the wall
    if (wall(1)) then
      wl(:, 0, :) = wr(:, 0, :)
      wl(:, 0, 2) = 2.0_wp * vwall(1) - wr(:, 0, 2)
      if (ns > n_euler) wl(:, 0, 7:8) = -wr(:, 0, 7:8)
    end if
    if (wall(2)) then
      wr(:, n, :) = wl(:, n, :)
      wr(:, n, 2) = 2.0_wp * vwall(2) - wl(:, n, 2)
      if (ns > n_euler) wr(:, n, 7:8) = -wl(:, n, 7:8)
    end if
    ! the sound speeds and the energies of the face states (one EOS pass for both)
    call eos_sound_speed2(eos, nf, wl(:, :, 1), wl(:, :, 5), cl, el)
    call eos_sound_speed2(eos, nf, wr(:, :, 1), wr(:, :, 5), cr, er)
    if (.not. all(wl(:, :, 1) > 0.0_wp .and. wr(:, :, 1) > 0.0_wp .and. cl > 0.0_wp &
        .and. cr > 0.0_wp)) then
      do i = 0, n
        do b = 1, nb
          if (wl(b, i, 1) > 0.0_wp .and. wr(b, i, 1) > 0.0_wp .and. cl(b, i) > 0.0_wp &
            .and. cr(b, i) > 0.0_wp) cycle
          nfallback = nfallback + 1
          wl(b, i, :) = pw(b, i, :)
          wr(b, i, :) = pw(b, i + 1, :)
          call eos_sound_speed2(eos, 1, wl(b, i, 1), wl(b, i, 5), cl(b, i), el(b, i))
          call eos_sound_speed2(eos, 1, wr(b, i, 1), wr(b, i, 5), cr(b, i), er(b, i))
          if (wl(b, i, 1) > 0.0_wp .and. wr(b, i, 1) > 0.0_wp .and. cl(b, i) > 0.0_wp &
            .and. cr(b, i) > 0.0_wp) cycle
          failed = .true.
          f = 0.0_wp
          return
        end do
      end do
    end if
    if (ns > n_euler) then
      ! longitudinal wave speed: bulk plus 4 G / (3 rho)
      cl = cl + (4.0_wp / 3.0_wp) * shear / wl(:, :, 1)
      cr = cr + (4.0_wp / 3.0_wp) * shear / wr(:, :, 1)
    end if
    cl = sqrt(max(cl, 0.0_wp))
    cr = sqrt(max(cr, 0.0_wp))
    if (ns > n_euler) then
      call flux_llf_solid(nf, ns, up, wl, wr, el, er, cl, cr, f, surf)
    else
      call face_flux(num%flux, nf, wl, wr, el, er, cl, cr, f)
    end if
    ! rho lambda: the mass flux times the upwind lambda (at a surface, the real cell's)
    if (nv > ns) then
      do i = 0, n
        do b = 1, nb
          f(b, i, nv) = f(b, i, 1) * merge(wl(b, i, nv), wr(b, i, nv), f(b, i, 1) >= 0.0_wp)
          if (surf(b, i) == 1) f(b, i, nv) = f(b, i, 1) * wl(b, i, nv)
          if (surf(b, i) == 2) f(b, i, nv) = f(b, i, 1) * wr(b, i, nv)
        end do
      end do
    end if
  end subroutine faces_and_fluxes

end module m_euler_faces
