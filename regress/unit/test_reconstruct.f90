!> Unit test of m_reconstruct: face values reconstructed from exact cell averages of a smooth
!> periodic function converge at the design order (eno1 1, eno2 2, eno3 3, weno5 5), measured
!> between n = 40 and n = 80 cells on the max norm over all faces.
program test_reconstruct
  use m_kinds, only: wp
  use m_reconstruct, only: reconstruct_faces, scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5
  use m_comm, only: comm_init, comm_exit
  implicit none
  integer, parameter :: schemes(4) = [scheme_eno1, scheme_eno2, scheme_eno3, scheme_weno5]
  real(wp), parameter :: need(4) = [0.9_wp, 1.8_wp, 2.7_wp, 4.5_wp]
  character(len=5), parameter :: names(4) = ['eno1 ', 'eno2 ', 'eno3 ', 'weno5']
  real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
  real(wp) :: err(2), order
  integer :: s, r, nfail
  call comm_init()
  nfail = 0
  do s = 1, 4
    do r = 1, 2
      err(r) = face_error(schemes(s), 40 * 2**(r - 1))
    end do
    order = log(err(1) / err(2)) / log(2.0_wp)
    write(6, '(a,a,es10.3,a,es10.3,a,f6.3)') names(s), ': error n=40 ', err(1), &
      ', n=80 ', err(2), ', order ', order
    if (order < need(s)) then
      nfail = nfail + 1
      write(6, '(a,f4.1)') '  order below ', need(s)
    end if
  end do
  if (nfail == 0) then
    write(6, '(a)') 'PASS test_reconstruct'
    call comm_exit(0)
  end if
  write(6, '(a)') 'FAIL test_reconstruct'
  call comm_exit(1)

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

  pure real(wp) function f(x)
    real(wp), intent(in) :: x
    f = sin(2.0_wp * pi * x) + 0.5_wp * cos(4.0_wp * pi * x)
  end function f

  pure real(wp) function prim(x)
    real(wp), intent(in) :: x
    prim = -cos(2.0_wp * pi * x) / (2.0_wp * pi) + 0.5_wp * sin(4.0_wp * pi * x) / (4.0_wp * pi)
  end function prim

end program test_reconstruct
