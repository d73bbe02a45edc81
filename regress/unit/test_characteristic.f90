!> Unit test of m_characteristic (manual/theory.md section 3.1): reconstruction in
!> characteristic variables
!> - keeps the design order on smooth gas data (rho, u, p of an ideal gas; eno3 3, weno5 5,
!>   max norm over all faces, n = 40 -> 80): the frozen basis is linear per face;
!> - on data linear along the pencil gives the primitive faces (ENO3 is exact there in any
!>   basis), for a gas and for a solid (Mie-Gruneisen, S_nn and G in the basis), with the
!>   other variables (tangential velocity, shear deviators, eps_p) as they are;
!> - at first order, and with variables = 'primitive', is reconstruct_faces bit for bit;
!> - gives the mirror image on mirrored data (u -> -u, the face order reversed).
program test_characteristic
  use m_kinds, only: wp
  use m_eos, only: eos_t, eos_ideal_gas, eos_mie_gruneisen
  use m_reconstruct, only: reconstruct_faces, scheme_eno1, scheme_eno3, scheme_weno5
  use m_characteristic, only: characteristic_work_t, characteristic_work_init, &
    reconstruct_pencils, variables_primitive, variables_characteristic
  use m_comm, only: comm_init
  use m_test_check, only: check_start, check, check_done
  implicit none
  real(wp), parameter :: pi = 4.0_wp * atan(1.0_wp)
  integer, parameter :: ng = 4
  type(eos_t) :: gas, copper
  integer, parameter :: schemes(2) = [scheme_eno3, scheme_weno5]
  character(len=5), parameter :: names(2) = ['eno3 ', 'weno5'], need_text(2) = ['2.7', '4.5']
  real(wp), parameter :: need(2) = [2.7_wp, 4.5_wp]
  real(wp) :: err(2), order
  integer :: r, s
  call comm_init()
  call check_start('test_characteristic')
  gas = eos_t(kind=eos_ideal_gas, gamma=1.4_wp, cv=1.0_wp)
  copper = eos_t(kind=eos_mie_gruneisen, rho0=8930.0_wp, c0=3940.0_wp, s=1.49_wp, &
    gruneisen=2.0_wp, cv=383.5_wp)
  do s = 1, 2
    do r = 1, 2
      err(r) = smooth_error(schemes(s), 40 * 2**(r - 1))
    end do
    order = log(err(1) / err(2)) / log(2.0_wp)
    write(6, '(a,a,2es10.3,a,f6.3)') names(s), ' characteristic: error n=40, 80 ', err, &
      ', order ', order
    call check(trim(names(s)) // ' characteristic: order at least ' // need_text(s), &
      order >= need(s))
  end do
  call linear_data(gas, .false., 5, 0.0_wp)
  call linear_data(copper, .true., 12, 43.33e9_wp)
  call mirrored(scheme_weno5)
  call mirrored(scheme_eno3)
  call check_done()

contains

  !> Max relative error of the face states of a smooth periodic gas state on [0, 1].
  real(wp) function smooth_error(scheme, n) result(err)
    integer, intent(in) :: scheme, n
    real(wp) :: v(1, 1-ng:n+ng, 5), left(1, 0:n, 5), right(1, 0:n, 5), dx, xf, ex(5)
    type(characteristic_work_t) :: work
    integer :: i, m
    dx = 1.0_wp / n
    do i = 1 - ng, n + ng
      v(1, i, :) = (antiderivative(i * dx) - antiderivative((i - 1) * dx)) / dx
    end do
    call characteristic_work_init(n + 1, 5, work)
    call reconstruct_pencils(scheme, variables_characteristic, gas, .false., 0.0_wp, 1, n, &
      ng, 5, v, left, right, 6, work)
    err = 0.0_wp
    do i = 0, n
      xf = i * dx
      ex = point(xf)
      do m = 1, 5
        err = max(err, abs(left(1, i, m) - ex(m)) / abs(ex(m)), &
          abs(right(1, i, m) - ex(m)) / abs(ex(m)))
      end do
    end do
  end function smooth_error

  !> rho, u, v, w, p at x: rho = 1 + 0.2 sin, u = 1 + 0.5 cos, v = w = 1, p = 2 + 0.3 sin
  function point(x) result(w)
    real(wp), intent(in) :: x
    real(wp) :: w(5)
    w = [1.0_wp + 0.2_wp * sin(2 * pi * x), 1.0_wp + 0.5_wp * cos(2 * pi * x), 1.0_wp, &
      1.0_wp, 2.0_wp + 0.3_wp * sin(4 * pi * x)]
  end function point

  !> The antiderivative of point (cell averages are its differences over dx)
  function antiderivative(x) result(w)
    real(wp), intent(in) :: x
    real(wp) :: w(5)
    w = [x - 0.2_wp * cos(2 * pi * x) / (2 * pi), x + 0.5_wp * sin(2 * pi * x) / (2 * pi), &
      x, x, 2.0_wp * x - 0.3_wp * cos(4 * pi * x) / (4 * pi)]
  end function antiderivative

  !> Data linear in i: characteristic faces equal the primitive ones (to rounding), and the
  !> first order and 'primitive' are reconstruct_faces bit for bit.
  subroutine linear_data(eos, solid, nv, shear)
    type(eos_t), intent(in) :: eos
    logical, intent(in) :: solid
    integer, intent(in) :: nv
    real(wp), intent(in) :: shear
    integer, parameter :: n = 12
    real(wp) :: v(2, 1-ng:n+ng, nv), base(nv), slope(nv)
    real(wp), dimension(2, 0:n, nv) :: cl, cr, pl, pr
    type(characteristic_work_t) :: work
    character(len=5) :: what
    integer :: i, m
    what = merge('solid', 'gas  ', solid)
    if (solid) then
      base = [9000.0_wp, 100.0_wp, 5.0_wp, -3.0_wp, 2.0e9_wp, -1.0e8_wp, 2.0e7_wp, 1.0e7_wp, &
        5.0e7_wp, 5.0e7_wp, 1.0e6_wp, 0.1_wp]
      slope = [20.0_wp, -7.0_wp, 1.0_wp, 0.5_wp, 3.0e7_wp, 2.0e6_wp, 1.0e5_wp, -2.0e5_wp, &
        -1.0e6_wp, -1.0e6_wp, 3.0e4_wp, 0.001_wp]
    else
      base = [1.0_wp, 0.3_wp, -0.2_wp, 0.1_wp, 1.0_wp]
      slope = [0.01_wp, 0.02_wp, -0.01_wp, 0.005_wp, 0.03_wp]
    end if
    do m = 1, nv
      do i = 1 - ng, n + ng
        v(1, i, m) = base(m) + slope(m) * i
        v(2, i, m) = base(m) - slope(m) * i
      end do
    end do
    call characteristic_work_init(2 * (n + 1), nv, work)
    call reconstruct_pencils(scheme_eno3, variables_characteristic, eos, solid, shear, 2, n, &
      ng, nv, v, cl, cr, 12, work)
    call reconstruct_faces(scheme_eno3, 2, n, ng, nv, v, pl, pr, 12)
    call check(what // ': eno3 characteristic faces of linear data are the primitive ones', &
      all(abs(cl - pl) <= 1.0e-12_wp * abs(pl) + 1.0e-9_wp) .and. &
      all(abs(cr - pr) <= 1.0e-12_wp * abs(pr) + 1.0e-9_wp))
    call reconstruct_pencils(scheme_eno1, variables_characteristic, eos, solid, shear, 2, n, &
      ng, nv, v, cl, cr, 12, work)
    call reconstruct_faces(scheme_eno1, 2, n, ng, nv, v, pl, pr, 12)
    call check(what // ': eno1 is the same in either variables, bit for bit', &
      all(abs(cl - pl) <= 0.0_wp) .and. all(abs(cr - pr) <= 0.0_wp))
    call reconstruct_pencils(scheme_weno5, variables_primitive, eos, solid, shear, 2, n, &
      ng, nv, v, cl, cr, 12, work)
    call reconstruct_faces(scheme_weno5, 2, n, ng, nv, v, pl, pr, 12)
    call check(what // ': variables primitive is reconstruct_faces, bit for bit', &
      all(abs(cl - pl) <= 0.0_wp) .and. all(abs(cr - pr) <= 0.0_wp))
  end subroutine linear_data

  !> A strong shock in a gas (pressure ratio 1e4) and its mirror image: the faces of the
  !> mirror are the mirror of the faces (u negated, left and right swapped).
  subroutine mirrored(scheme)
    integer, intent(in) :: scheme
    integer, parameter :: n = 10
    real(wp) :: v(2, 1-ng:n+ng, 5), left(2, 0:n, 5), right(2, 0:n, 5)
    type(characteristic_work_t) :: work
    integer :: i
    do i = 1 - ng, n + ng
      if (i <= n / 2) then
        v(1, i, :) = [4.0_wp, 3.0_wp, 0.1_wp, 0.0_wp, 1.0e3_wp]
      else
        v(1, i, :) = [1.0_wp, 0.0_wp, 0.2_wp, 0.0_wp, 0.1_wp]
      end if
      if (i == n / 2) v(1, i, :) = [2.5_wp, 1.5_wp, 0.15_wp, 0.0_wp, 4.0e2_wp]
    end do
    do i = 1 - ng, n + ng
      v(2, i, :) = v(1, n + 1 - i, :)
      v(2, i, 2) = -v(1, n + 1 - i, 2)
    end do
    call characteristic_work_init(2 * (n + 1), 5, work)
    call reconstruct_pencils(scheme, variables_characteristic, gas, .false., 0.0_wp, 2, n, ng, &
      5, v, left, right, 6, work)
    right(2, :, 2) = -right(2, :, 2)
    call check('mirrored shock: the faces are mirrored (scheme ' // achar(48 + scheme) // ')', &
      all(abs(left(1, :, :) - right(2, n:0:-1, :)) <= 1.0e-13_wp * abs(left(1, :, :))))
  end subroutine mirrored

end program test_characteristic
