!> Right-hand side of the Euler equations on one block (manual/theory.md eq. 1 and 3):
!> L(U) = -sum_d dF_d/dx_d + S, dimension by dimension. Primitive variables
!> (rho, u, v, w, p) are reconstructed on each pencil (m_reconstruct), face states that are
!> not admissible (rho <= 0 or c^2 <= 0) fall back to the first-order cell values and are
!> counted, and the face flux (m_flux) is differenced. In axisymmetric geometry (x = r,
!> y = z) the geometric source S = -(u / r) (rho, rho u, rho v, 0, rho E + p) is added.
!> Also here: the largest signal rate for the CFL step and the RK stage update.
!> Kernels only: no MPI, no I/O, no allocation in the loops (workspace is allocated once).
module m_euler
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_pressure, eos_energy, eos_sound_speed2
  use m_reconstruct, only: reconstruct_faces
  use m_flux, only: face_flux
  use m_state, only: i_rho, i_mx, i_my, i_mz, i_en
  use m_layout, only: layout_t
  implicit none
  private
  public :: euler_work_t, euler_work_init, euler_rhs, euler_max_rate, rk_stage_update
  public :: primitive_row

  !> Scratch space for one block and one pencil, allocated once per run.
  type :: euler_work_t
    real(wp), allocatable :: prim(:, :, :, :)      !< (padded block, 5): rho, u, v, w, p
    real(wp), allocatable :: pw(:, :)              !< pencil of primitives (1-ng:n+ng, 5)
    real(wp), allocatable :: wl(:, :), wr(:, :)    !< face states (0:n, 5)
    real(wp), allocatable :: f(:, :)               !< face fluxes (0:n, 5)
    real(wp), allocatable :: el(:), er(:), cl(:), cr(:)
    real(wp), allocatable :: row(:)
  end type euler_work_t

contains

  subroutine euler_work_init(lay, work)
    type(layout_t), intent(in) :: lay
    type(euler_work_t), intent(out) :: work
    integer :: lo(3), hi(3), nmax, gmax
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    nmax = maxval(lay%bsize)
    gmax = maxval(lay%ng)
    allocate(work%prim(lo(1):hi(1), lo(2):hi(2), lo(3):hi(3), 5))
    allocate(work%pw(1-gmax:nmax+gmax, 5), work%wl(0:nmax, 5), work%wr(0:nmax, 5))
    allocate(work%f(0:nmax, 5), work%el(0:nmax), work%er(0:nmax), work%cl(0:nmax))
    allocate(work%cr(0:nmax), work%row(lo(1):hi(1)))
  end subroutine euler_work_init

  !> Primitive variables (rho, u, v, w, p) of one row of cells i = lo..hi.
  subroutine primitive_row(eos, n, q_rho, q_mx, q_my, q_mz, q_en, rho, u, v, w, p, e)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: n
    real(wp), intent(in) :: q_rho(n), q_mx(n), q_my(n), q_mz(n), q_en(n)
    real(wp), intent(out) :: rho(n), u(n), v(n), w(n), p(n), e(n)
    real(wp) :: rinv
    integer :: i
    do i = 1, n
      rho(i) = q_rho(i)
      rinv = 1.0_wp / q_rho(i)
      u(i) = q_mx(i) * rinv
      v(i) = q_my(i) * rinv
      w(i) = q_mz(i) * rinv
      e(i) = q_en(i) * rinv - 0.5_wp * (u(i)**2 + v(i)**2 + w(i)**2)
    end do
    call eos_pressure(eos, n, rho, e, p)
  end subroutine primitive_row

  !> rhs = L(q) over the interior of one block; nfallback counts faces that fell back to
  !> first order.
  subroutine euler_rhs(lay, eos, scheme, flux_kind, q, rhs, offset, work, nfallback)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: scheme, flux_kind, offset(3)
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(out) :: rhs(:, :, :, :)
    type(euler_work_t), intent(inout) :: work
    integer, intent(inout) :: nfallback
    integer :: lo(3), hi(3), j, k, d, n, g, i, perm(5), nr
    real(wp) :: rdx, r, ur
    lo = 1 - lay%ng
    hi = lay%bsize + lay%ng
    nr = hi(1) - lo(1) + 1
    do k = lo(3), hi(3)
      do j = lo(2), hi(2)
        call primitive_row(eos, nr, q(:, j, k, i_rho), q(:, j, k, i_mx), q(:, j, k, i_my), &
          q(:, j, k, i_mz), q(:, j, k, i_en), work%prim(:, j, k, 1), work%prim(:, j, k, 2), &
          work%prim(:, j, k, 3), work%prim(:, j, k, 4), work%prim(:, j, k, 5), work%row)
      end do
    end do
    rhs = 0.0_wp
    do d = 1, lay%ndim
      n = lay%bsize(d)
      g = lay%ng(d)
      rdx = 1.0_wp / lay%dx(d)
      ! pencil frame: (rho, u_normal, u_t1, u_t2, p)
      select case (d)
      case (1)
        perm = [1, 2, 3, 4, 5]
      case (2)
        perm = [1, 3, 2, 4, 5]
      case default
        perm = [1, 4, 2, 3, 5]
      end select
      do k = 1, merge(1, lay%bsize(3), d == 3)
        do j = 1, merge(1, lay%bsize(2), d == 2)
          do i = 1, merge(1, lay%bsize(1), d == 1)
            call gather(d, i, j, k)
            call pencil_flux(n, g)
            call scatter(d, i, j, k)
          end do
        end do
      end do
    end do
    if (lay%axisymmetric) then
      do k = 1, lay%bsize(3)
        do j = 1, lay%bsize(2)
          do i = 1, lay%bsize(1)
            r = lay%lo(1) + (real(offset(1) + i, wp) - 0.5_wp) * lay%dx(1)
            rhs(i, j, k, i_rho) = rhs(i, j, k, i_rho) - q(i, j, k, i_mx) / r
            ur = work%prim(i, j, k, 2) / r
            rhs(i, j, k, i_mx) = rhs(i, j, k, i_mx) - q(i, j, k, i_mx) * ur
            rhs(i, j, k, i_my) = rhs(i, j, k, i_my) - q(i, j, k, i_my) * ur
            rhs(i, j, k, i_en) = rhs(i, j, k, i_en) &
              - (q(i, j, k, i_en) + work%prim(i, j, k, 5)) * ur
          end do
        end do
      end do
    end if

  contains

    subroutine gather(dd, i0, j0, k0)
      integer, intent(in) :: dd, i0, j0, k0
      integer :: mm
      do mm = 1, 5
        select case (dd)
        case (1)
          work%pw(1-g:n+g, mm) = work%prim(1-g:n+g, j0, k0, perm(mm))
        case (2)
          work%pw(1-g:n+g, mm) = work%prim(i0, 1-g:n+g, k0, perm(mm))
        case default
          work%pw(1-g:n+g, mm) = work%prim(i0, j0, 1-g:n+g, perm(mm))
        end select
      end do
    end subroutine gather

    subroutine scatter(dd, i0, j0, k0)
      integer, intent(in) :: dd, i0, j0, k0
      integer :: mm, qm
      do mm = 1, 5
        qm = perm(mm)
        select case (dd)
        case (1)
          rhs(1:n, j0, k0, qm) = rhs(1:n, j0, k0, qm) &
            - rdx * (work%f(1:n, mm) - work%f(0:n-1, mm))
        case (2)
          rhs(i0, 1:n, k0, qm) = rhs(i0, 1:n, k0, qm) &
            - rdx * (work%f(1:n, mm) - work%f(0:n-1, mm))
        case default
          rhs(i0, j0, 1:n, qm) = rhs(i0, j0, 1:n, qm) &
            - rdx * (work%f(1:n, mm) - work%f(0:n-1, mm))
        end select
      end do
    end subroutine scatter

    subroutine pencil_flux(nn, gg)
      integer, intent(in) :: nn, gg
      call faces_and_fluxes(eos, scheme, flux_kind, nn, gg, work%pw(1-gg:nn+gg, :), &
        work%wl(0:nn, :), work%wr(0:nn, :), work%el(0:nn), work%er(0:nn), work%cl(0:nn), &
        work%cr(0:nn), work%f(0:nn, :), nfallback)
    end subroutine pencil_flux

  end subroutine euler_rhs

  !> Face states and fluxes of one pencil of n cells: reconstruct, test admissibility (falling
  !> back to the cell values where a face state has rho <= 0 or c^2 <= 0), then the flux.
  subroutine faces_and_fluxes(eos, scheme, flux_kind, n, g, pw, wl, wr, el, er, cl, cr, f, &
      nfallback)
    type(eos_t), intent(in) :: eos
    integer, intent(in) :: scheme, flux_kind, n, g
    real(wp), intent(in) :: pw(1-g:n+g, 5)
    real(wp), intent(out) :: wl(0:n, 5), wr(0:n, 5), el(0:n), er(0:n), cl(0:n), cr(0:n)
    real(wp), intent(out) :: f(0:n, 5)
    integer, intent(inout) :: nfallback
    integer :: i
    call reconstruct_faces(scheme, n, g, 5, pw, wl, wr)
    call eos_sound_speed2(eos, n + 1, wl(:, 1), wl(:, 5), cl)
    call eos_sound_speed2(eos, n + 1, wr(:, 1), wr(:, 5), cr)
    do i = 0, n
      if (wl(i, 1) > 0.0_wp .and. wr(i, 1) > 0.0_wp .and. cl(i) > 0.0_wp &
        .and. cr(i) > 0.0_wp) cycle
      nfallback = nfallback + 1
      wl(i, :) = pw(i, :)
      wr(i, :) = pw(i + 1, :)
      call eos_sound_speed2(eos, 1, wl(i:i, 1), wl(i:i, 5), cl(i:i))
      call eos_sound_speed2(eos, 1, wr(i:i, 1), wr(i:i, 5), cr(i:i))
    end do
    cl = sqrt(max(cl, 0.0_wp))
    cr = sqrt(max(cr, 0.0_wp))
    call eos_energy(eos, n + 1, wl(:, 1), wl(:, 5), el)
    call eos_energy(eos, n + 1, wr(:, 1), wr(:, 5), er)
    call face_flux(flux_kind, n + 1, wl, wr, el, er, cl, cr, f)
  end subroutine faces_and_fluxes

  !> Largest sum over directions of (|u_d| + c) / dx_d over the interior: dt = cfl / rate.
  !> Also reports whether every interior cell is admissible (rho > 0, c^2 > 0, finite).
  subroutine euler_max_rate(lay, eos, q, rate, admissible)
    type(layout_t), intent(in) :: lay
    type(eos_t), intent(in) :: eos
    real(wp), intent(in) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(out) :: rate
    logical, intent(out) :: admissible
    integer :: j, k, i, n
    real(wp) :: r, c2(lay%bsize(1)), rdx(3)
    real(wp) :: rho(lay%bsize(1)), u(lay%bsize(1)), v(lay%bsize(1)), w(lay%bsize(1))
    real(wp) :: p(lay%bsize(1)), e(lay%bsize(1))
    n = lay%bsize(1)
    rdx = 0.0_wp
    rdx(1:lay%ndim) = 1.0_wp / lay%dx(1:lay%ndim)
    rate = 0.0_wp
    admissible = .true.
    do k = 1, lay%bsize(3)
      do j = 1, lay%bsize(2)
        if (any(.not. (q(1:n, j, k, i_rho) > 0.0_wp))) then
          admissible = .false.
          cycle
        end if
        call primitive_row(eos, n, q(1:n, j, k, i_rho), q(1:n, j, k, i_mx), &
          q(1:n, j, k, i_my), q(1:n, j, k, i_mz), q(1:n, j, k, i_en), rho, u, v, w, p, e)
        call eos_sound_speed2(eos, n, rho, p, c2)
        do i = 1, n
          if (.not. (c2(i) > 0.0_wp .and. c2(i) < huge(1.0_wp))) then
            admissible = .false.
            cycle
          end if
          r = sqrt(c2(i)) * sum(rdx) + abs(u(i)) * rdx(1) + abs(v(i)) * rdx(2) &
            + abs(w(i)) * rdx(3)
          rate = max(rate, r)
        end do
      end do
    end do
  end subroutine euler_max_rate

  !> TVD Runge-Kutta stage (Shu and Osher 1988): q = a q0 + b (q + dt rhs) on the interior.
  subroutine rk_stage_update(lay, stage, order, dt, q, q0, rhs)
    type(layout_t), intent(in) :: lay
    integer, intent(in) :: stage, order
    real(wp), intent(in) :: dt
    real(wp), intent(inout) :: q(1-lay%ng(1):, 1-lay%ng(2):, 1-lay%ng(3):, :)
    real(wp), intent(inout) :: q0(:, :, :, :)
    real(wp), intent(in) :: rhs(:, :, :, :)
    real(wp) :: a, b
    integer :: n1, n2, n3
    n1 = lay%bsize(1)
    n2 = lay%bsize(2)
    n3 = lay%bsize(3)
    if (stage == 1) then
      q0 = q(1:n1, 1:n2, 1:n3, :)
      q(1:n1, 1:n2, 1:n3, :) = q0 + dt * rhs
      return
    end if
    if (order == 2) then
      a = 0.5_wp
    else if (stage == 2) then
      a = 0.75_wp
    else
      a = 1.0_wp / 3.0_wp
    end if
    b = 1.0_wp - a
    q(1:n1, 1:n2, 1:n3, :) = a * q0 + b * (q(1:n1, 1:n2, 1:n3, :) + dt * rhs)
  end subroutine rk_stage_update

end module m_euler
