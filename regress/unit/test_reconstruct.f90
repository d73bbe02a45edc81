!> Unit test of m_reconstruct: face values reconstructed from exact cell averages of a smooth
!> periodic function converge at the design order (eno1 1, eno2 2, eno3 3, weno5 5), measured
!> between n = 40 and n = 80 cells on the max norm over all faces. And the bound of
!> bound_faces (manual/theory.md 5.1e): a step and a spike of a scalar phi in [0, 1],
!> carried conservatively as rho phi by the mass flux with upwind face values through a
!> non-uniform density, stay within [0, 1] with bounded faces (eno2, eno3, weno5) and leave it
!> without (eno3, weno5: the check can fail).
program test_reconstruct
  use m_kinds, only: wp
  use m_reconstruct, only: reconstruct_faces, scheme_eno1, scheme_eno2, scheme_eno3, &
    scheme_weno5
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_done
  implicit none
  integer, parameter :: schemes(4) = [scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5]
  real(wp), parameter :: need(4) = [0.9_wp, 1.8_wp, 2.7_wp, 4.5_wp]
  character(len=5), parameter :: names(4) = ['eno1 ', 'eno2 ', 'eno3 ', 'weno5']
  real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
  real(wp) :: err(2), order, range(2)
  integer :: s, r
  call comm_init()
  call check_start('test_reconstruct')
  do s = 1, 4
    do r = 1, 2
      err(r) = face_error(schemes(s), 40 * 2**(r - 1))
    end do
    order = log(err(1) / err(2)) / log(2.0_wp)
    write(6, '(a,a,es10.3,a,es10.3,a,f6.3)') names(s), ': error n=40 ', err(1), &
      ', n=80 ', err(2), ', order ', order
    call check(trim(names(s)) // ': order at least ' // order_text(need(s)), order >= need(s))
  end do
  do s = 2, 4
    range = transport_range(schemes(s), .true.)
    write(6, '(a,a,2es11.3)') names(s), ': bounded transport, phi min, max - 1', range(1), &
      range(2) - 1.0_wp
    call check(trim(names(s)) // ': phi stays in [0, 1] with bounded faces', &
      range(1) >= -1.0e-14_wp .and. range(2) <= 1.0_wp + 1.0e-14_wp)
    if (s == 2) cycle
    range = transport_range(schemes(s), .false.)
    write(6, '(a,a,2es11.3)') names(s), ': unbounded faces, phi min, max - 1', range(1), &
      range(2) - 1.0_wp
    call check(trim(names(s)) // ': unbounded faces leave [0, 1] (else the check is blind)', &
      range(1) < -1.0e-10_wp .or. range(2) > 1.0_wp + 1.0e-10_wp)
  end do
  call check_done()

contains

  !> Max error of both face states of f(x) = sin(2 pi x) + 0.5 cos(4 pi x) on [0, 1].
  real(wp) function face_error(scheme, n) result(err)
    integer, intent(in) :: scheme, n
    integer, parameter :: ng = 4
    real(wp) :: v(1, 1-ng:n+ng, 1), left(1, 0:n, 1), right(1, 0:n, 1), dx, xf
    integer :: i
    dx = 1.0_wp / n
    do i = 1 - ng, n + ng
      v(1, i, 1) = (prim(i * dx) - prim((i - 1) * dx)) / dx
    end do
    call reconstruct_faces(scheme, 1, n, ng, 1, v, left, right)
    err = 0.0_wp
    do i = 0, n
      xf = i * dx
      err = max(err, abs(left(1, i, 1) - f(xf)), abs(right(1, i, 1) - f(xf)))
    end do
  end function face_error

  !> min and max of phi over 150 SSP-RK3 steps of u = 1 on a periodic grid of 100 cells,
  !> rho = 1 + 0.5 sin(2 pi x), phi a step (0.2 < x < 0.5) and a one-cell spike; the mass
  !> outflow of a face per stage stays below the bound's 1/6 of the cell's mass.
  function transport_range(scheme, bounded) result(range)
    integer, intent(in) :: scheme
    logical, intent(in) :: bounded
    real(wp) :: range(2)
    integer, parameter :: n = 100, ng = 4
    real(wp), parameter :: lam = 0.1_wp   ! dt / dx
    real(wp) :: q(n, 2), q0(n, 2), rhs(n, 2)
    integer :: step, stage, i
    do i = 1, n
      q(i, 1) = 1.0_wp + 0.5_wp * sin(2.0_wp * pi * (i - 0.5_wp) / n)
      q(i, 2) = 0.0_wp
      if (i > 20 .and. i <= 50) q(i, 2) = q(i, 1)
      if (i == 75) q(i, 2) = q(i, 1)
    end do
    range = [1.0_wp, 0.0_wp]
    do step = 1, 150
      q0 = q
      do stage = 1, 3
        call transport_rhs(scheme, bounded, n, ng, q, rhs)
        q = q + lam * rhs
        if (stage == 2) q = 0.75_wp * q0 + 0.25_wp * q
        if (stage == 3) q = (q0 + 2.0_wp * q) / 3.0_wp
      end do
      range = [min(range(1), minval(q(:, 2) / q(:, 1))), &
        max(range(2), maxval(q(:, 2) / q(:, 1)))]
    end do
  end function transport_range

  !> -d(F)/dx of (rho, rho phi) on the periodic grid: upwind faces of u = 1
  subroutine transport_rhs(scheme, bounded, n, ng, qq, r)
    integer, intent(in) :: scheme, n, ng
    logical, intent(in) :: bounded
    real(wp), intent(in) :: qq(n, 2)
    real(wp), intent(out) :: r(n, 2)
    real(wp) :: v(1, 1-ng:n+ng, 2), left(1, 0:n, 2), right(1, 0:n, 2), fm(0:n), fs(0:n)
    integer :: ii
    do ii = 1 - ng, n + ng
      v(1, ii, 1) = qq(modulo(ii - 1, n) + 1, 1)
      v(1, ii, 2) = qq(modulo(ii - 1, n) + 1, 2) / v(1, ii, 1)
    end do
    if (bounded) then
      call reconstruct_faces(scheme, 1, n, ng, 2, v, left, right, bounded_from=2)
    else
      call reconstruct_faces(scheme, 1, n, ng, 2, v, left, right)
    end if
    fm = left(1, :, 1)          ! u = 1: the upwind state carries the mass
    fs = fm * left(1, :, 2)
    r(:, 1) = -(fm(1:n) - fm(0:n-1))
    r(:, 2) = -(fs(1:n) - fs(0:n-1))
  end subroutine transport_rhs

  function order_text(x) result(t)
    real(wp), intent(in) :: x
    character(len=4) :: t
    write(t, '(f4.1)') x
  end function order_text

  pure real(wp) function f(x)
    real(wp), intent(in) :: x
    f = sin(2.0_wp * pi * x) + 0.5_wp * cos(4.0_wp * pi * x)
  end function f

  pure real(wp) function prim(x)
    real(wp), intent(in) :: x
    prim = -cos(2.0_wp * pi * x) / (2.0_wp * pi) + 0.5_wp * sin(4.0_wp * pi * x) / (4.0_wp * pi)
  end function prim

end program test_reconstruct
