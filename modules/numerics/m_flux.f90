!> Numerical fluxes of the Euler equations across the faces of one pencil
!> (manual/theory.md section 3): local Lax-Friedrichs (Rusanov) and HLLC (Toro, Spruce and
!> Speares 1994) with Davis wave-speed estimates. States are primitive, in the frame of the
!> pencil: (rho, u_normal, u_t1, u_t2, p), with the specific internal energy e and the sound
!> speed c supplied by the caller (from the EOS), so the flux is EOS-independent.
!> For solids (eq. 5.1a) the flux is LLF, with a choice for the material-advected scalars
!> rho eps_p and rho w_c (eq. 5.1b): LLF, or the mass flux times the specific value upwinded
!> by its sign (Larrouturou 1991).
module m_flux
  use m_kinds, only: wp
  use m_state, only: i_epsp
  use m_text, only: choice_index
  implicit none
  private
  public :: flux_from_name, flux_kind_llf, flux_kind_hllc, face_flux
  public :: flux_llf_solid, scalar_flux_from_name, scalar_flux_llf, scalar_flux_upwind
  public :: flux_names, scalar_flux_names

  integer, parameter :: flux_kind_llf = 1, flux_kind_hllc = 2
  integer, parameter :: scalar_flux_llf = 1, scalar_flux_upwind = 2
  !> the deck's names (&numerics flux, scalar_flux): name k stands for kind k
  character(len=4), parameter :: flux_names(2) = [character(len=4) :: 'llf', 'hllc']
  character(len=6), parameter :: scalar_flux_names(2) = [character(len=6) :: 'llf', 'upwind']
  !> the first of the passive scalars (rho eps_p, rho w_c) in the pencil frame, which keeps
  !> them at their places in the state vector
  integer, parameter :: first_scalar = i_epsp

contains

  !> The flux kind of a deck name (flux_names), and of a scalar flux (scalar_flux_names).
  integer function flux_from_name(name) result(kind)
    character(len=*), intent(in) :: name
    kind = choice_index(flux_names, name, 'flux_from_name')
  end function flux_from_name

  integer function scalar_flux_from_name(name) result(kind)
    character(len=*), intent(in) :: name
    kind = choice_index(scalar_flux_names, name, 'scalar_flux_from_name')
  end function scalar_flux_from_name

  !> The Euler flux of kind flux_kind_llf or flux_kind_hllc across nf faces, from the pencil
  !> frame states w = (rho, u_n, u_t1, u_t2, p) left and right of each face, their specific
  !> internal energies e and sound speeds c. The two Riemann solvers share these arguments
  !> (their contained procedures see them) and differ only in their loop over the faces.
  subroutine face_flux(kind, nf, wl, wr, el, er, cl, cr, f)
    integer, intent(in) :: kind, nf
    real(wp), intent(in) :: wl(nf, 5), wr(nf, 5), el(nf), er(nf), cl(nf), cr(nf)
    real(wp), intent(out) :: f(nf, 5)
    if (kind == flux_kind_hllc) then
      call flux_hllc()
    else
      call flux_llf()
    end if

  contains

    subroutine flux_llf()
      real(wp) :: a, ml, mr, enl, enr, kl, kr
      integer :: i
      do i = 1, nf
        a = max(abs(wl(i, 2)) + cl(i), abs(wr(i, 2)) + cr(i))
        ml = wl(i, 1) * wl(i, 2)
        mr = wr(i, 1) * wr(i, 2)
        kl = 0.5_wp * (wl(i, 2)**2 + wl(i, 3)**2 + wl(i, 4)**2)
        kr = 0.5_wp * (wr(i, 2)**2 + wr(i, 3)**2 + wr(i, 4)**2)
        enl = wl(i, 1) * (el(i) + kl)
        enr = wr(i, 1) * (er(i) + kr)
        f(i, 1) = 0.5_wp * (ml + mr - a * (wr(i, 1) - wl(i, 1)))
        f(i, 2) = 0.5_wp * (ml * wl(i, 2) + wl(i, 5) + mr * wr(i, 2) + wr(i, 5) &
          - a * (wr(i, 1) * wr(i, 2) - wl(i, 1) * wl(i, 2)))
        f(i, 3) = 0.5_wp * (ml * wl(i, 3) + mr * wr(i, 3) &
          - a * (wr(i, 1) * wr(i, 3) - wl(i, 1) * wl(i, 3)))
        f(i, 4) = 0.5_wp * (ml * wl(i, 4) + mr * wr(i, 4) &
          - a * (wr(i, 1) * wr(i, 4) - wl(i, 1) * wl(i, 4)))
        f(i, 5) = 0.5_wp * ((enl + wl(i, 5)) * wl(i, 2) + (enr + wr(i, 5)) * wr(i, 2) &
          - a * (enr - enl))
      end do
    end subroutine flux_llf

    subroutine flux_hllc()
      real(wp) :: sl, sr, ss, enl, enr
      integer :: i
      do i = 1, nf
        sl = min(wl(i, 2) - cl(i), wr(i, 2) - cr(i))
        sr = max(wl(i, 2) + cl(i), wr(i, 2) + cr(i))
        enl = wl(i, 1) * (el(i) + 0.5_wp * (wl(i, 2)**2 + wl(i, 3)**2 + wl(i, 4)**2))
        enr = wr(i, 1) * (er(i) + 0.5_wp * (wr(i, 2)**2 + wr(i, 3)**2 + wr(i, 4)**2))
        ss = (wr(i, 5) - wl(i, 5) + wl(i, 1) * wl(i, 2) * (sl - wl(i, 2)) &
          - wr(i, 1) * wr(i, 2) * (sr - wr(i, 2))) &
          / (wl(i, 1) * (sl - wl(i, 2)) - wr(i, 1) * (sr - wr(i, 2)))
        if (ss >= 0.0_wp) then
          f(i, :) = hllc_side(wl(i, 1), wl(i, 2), wl(i, 3), wl(i, 4), wl(i, 5), enl, sl, ss, &
            sl >= 0.0_wp)
        else
          f(i, :) = hllc_side(wr(i, 1), wr(i, 2), wr(i, 3), wr(i, 4), wr(i, 5), enr, sr, ss, &
            sr <= 0.0_wp)
        end if
      end do
    end subroutine flux_hllc

  end subroutine face_flux

  !> The HLLC flux on the side of the contact that the face sees: that side's state (rho,
  !> u_n, u_t1, u_t2, p), total energy en and wave speed s; beyond the wave (supersonic)
  !> its Euler flux, else that flux plus s times the jump to the star state.
  pure function hllc_side(rho, un, ut1, ut2, p, en, s, ss, supersonic) result(f)
    real(wp), intent(in) :: rho, un, ut1, ut2, p, en, s, ss
    logical, intent(in) :: supersonic
    real(wp) :: f(5), u(5), us(5), fac
    call euler_flux(rho, un, ut1, ut2, p, en, f)
    if (supersonic) return
    u = [rho, rho * un, rho * ut1, rho * ut2, en]
    fac = rho * (s - un) / (s - ss)
    us = fac * [1.0_wp, ss, ut1, ut2, en / rho + (ss - un) * (ss + p / (rho * (s - un)))]
    f = f + s * (us - u)
  end function hllc_side

  pure subroutine euler_flux(rho, un, ut1, ut2, p, en, f)
    real(wp), intent(in) :: rho, un, ut1, ut2, p, en
    real(wp), intent(out) :: f(5)
    f(1) = rho * un
    f(2) = f(1) * un + p
    f(3) = f(1) * ut1
    f(4) = f(1) * ut2
    f(5) = (en + p) * un
  end subroutine euler_flux

  !> Local Lax-Friedrichs flux of the elastic-plastic equations (manual/theory.md eq. 5.1) in
  !> the pencil frame: w = (rho, u_n, u_t1, u_t2, p, S_nn, S_nt1, S_nt2, three more stress
  !> components, eps_p, w_c). The stress enters the momentum and energy fluxes as the
  !> traction -(S_nn, S_nt1, S_nt2); rho S, rho eps_p and rho w_c are advected. c is the
  !> longitudinal speed sqrt(c_bulk^2 + 4 G / (3 rho)), supplied by the caller.
  !> On the faces where upwind is true the scalars eps_p and w_c, which only move with the
  !> material, are carried by the mass flux F_rho with the upwind specific value (eq. 5.1b):
  !> their LLF dissipation a (rho phi_R - rho phi_L) / 2, with a ~ c_L, smears them where
  !> the material hardly moves (a stagnation point on a wall). Uniform phi stays uniform,
  !> and under the CFL condition of the mass update phi stays within its neighbours' range
  !> at first order. The stress keeps its LLF dissipation: it is the only dissipation of the
  !> elastic waves, whose coupling to the velocity is in the source (eq. 5.1).
  subroutine flux_llf_solid(nf, nv, upwind, wl, wr, el, er, cl, cr, f, surface)
    integer, intent(in) :: nf, nv
    logical, intent(in) :: upwind(nf)    !< faces whose scalars take the upwind flux
    !> faces on a body's surface: 1 the left cell is real and the right one a ghost, 2 the
    !> other way round, 0 neither; there the transported variables (S, eps_p, w_c) move with
    !> the mass flux at the real cell's value (their ghost values serve the traction only)
    integer, intent(in), optional :: surface(nf)
    real(wp), intent(in) :: wl(nf, nv), wr(nf, nv), el(nf), er(nf), cl(nf), cr(nf)
    real(wp), intent(out) :: f(nf, nv)
    real(wp) :: a(nf), ml, mr, enl, enr
    integer :: i, m
    a = max(abs(wl(:, 2)) + cl, abs(wr(:, 2)) + cr)
    do i = 1, nf
      ml = wl(i, 1) * wl(i, 2)
      mr = wr(i, 1) * wr(i, 2)
      enl = wl(i, 1) * (el(i) + 0.5_wp * (wl(i, 2)**2 + wl(i, 3)**2 + wl(i, 4)**2))
      enr = wr(i, 1) * (er(i) + 0.5_wp * (wr(i, 2)**2 + wr(i, 3)**2 + wr(i, 4)**2))
      f(i, 1) = 0.5_wp * (ml + mr - a(i) * (wr(i, 1) - wl(i, 1)))
      f(i, 2) = 0.5_wp * (ml * wl(i, 2) + wl(i, 5) - wl(i, 6) + mr * wr(i, 2) + wr(i, 5) &
        - wr(i, 6) - a(i) * (wr(i, 1) * wr(i, 2) - wl(i, 1) * wl(i, 2)))
      f(i, 3) = 0.5_wp * (ml * wl(i, 3) - wl(i, 7) + mr * wr(i, 3) - wr(i, 7) &
        - a(i) * (wr(i, 1) * wr(i, 3) - wl(i, 1) * wl(i, 3)))
      f(i, 4) = 0.5_wp * (ml * wl(i, 4) - wl(i, 8) + mr * wr(i, 4) - wr(i, 8) &
        - a(i) * (wr(i, 1) * wr(i, 4) - wl(i, 1) * wl(i, 4)))
      f(i, 5) = 0.5_wp * ((enl + wl(i, 5) - wl(i, 6)) * wl(i, 2) - wl(i, 7) * wl(i, 3) &
        - wl(i, 8) * wl(i, 4) + (enr + wr(i, 5) - wr(i, 6)) * wr(i, 2) &
        - wr(i, 7) * wr(i, 3) - wr(i, 8) * wr(i, 4) - a(i) * (enr - enl))
    end do
    do m = 6, nv
      do i = 1, nf
        f(i, m) = 0.5_wp * (wl(i, 1) * wl(i, m) * wl(i, 2) + wr(i, 1) * wr(i, m) * wr(i, 2) &
          - a(i) * (wr(i, 1) * wr(i, m) - wl(i, 1) * wl(i, m)))
      end do
    end do
    if (any(upwind)) then
      do m = first_scalar, nv
        do i = 1, nf
          if (upwind(i)) f(i, m) = f(i, 1) * merge(wl(i, m), wr(i, m), f(i, 1) >= 0.0_wp)
        end do
      end do
    end if
    if (.not. present(surface)) return
    do m = 6, nv
      do i = 1, nf
        if (surface(i) == 1) f(i, m) = f(i, 1) * wl(i, m)
        if (surface(i) == 2) f(i, m) = f(i, 1) * wr(i, m)
      end do
    end do
  end subroutine flux_llf_solid

end module m_flux
