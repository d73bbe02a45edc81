!> Reconstruction in characteristic variables (manual/theory.md section 3.1, eqs. 3.1-3.3):
!> the face states of a bundle of pencils reconstructed in the variables of the waves that
!> cross the face (&numerics variables = 'characteristic') rather than in the primitive ones.
!> For every face the stencil's primitive values (rho, u_n, p; with strength also S_nn) are
!> projected on the left eigenvectors of the 1D system frozen at the face's mean state,
!> reconstructed there by m_reconstruct's ENO/WENO, and projected back (eq. 3.2). The
!> eigenvectors are those of the primitive system, so the EOS enters only through the sound
!> speed c (any p(rho, e)); with strength the acoustic pair is (u, sigma = S_nn - p) at the
!> longitudinal speed a^2 = c^2 + 4 G / (3 rho), the deviator's elastic part rides with the
!> material (eq. 3.2; the Gruneisen term Gamma S_nn / rho of a^2, 0.4 % of c^2 in copper at
!> Y = 0.4 GPa, is left out: a frozen basis need not be exact, its inverse is). Tangential
!> velocities and the other variables (shear deviators, eps_p, w_c,
!> rho lambda) are reconstructed as they are. A face whose mean state has no sound speed
!> keeps the primitive reconstruction. Without the choice, or at first order, this is
!> m_reconstruct's reconstruct_faces unchanged. Kernels only: no MPI, no I/O; workspace is
!> allocated once (characteristic_work_init).
module m_characteristic
  use m_kinds, only: wp
  use m_text, only: choice_index
  use m_eos, only: eos_t, eos_sound_speed2
  use m_reconstruct, only: reconstruct_faces, scheme_eno1
  implicit none
  private
  public :: variables_primitive, variables_characteristic, variables_names, variables_from_name
  public :: characteristic_work_t, characteristic_work_init, reconstruct_pencils

  integer, parameter :: variables_primitive = 1, variables_characteristic = 2
  !> the deck's names (&numerics variables), in the order of the codes above
  character(len=14), parameter :: variables_names(2) = [character(len=14) :: 'primitive', &
    'characteristic']

  !> Workspace of one bundle of nf faces: the 6-cell stencil of every face in characteristic
  !> variables, its two face values, and the face's reference state.
  type :: characteristic_work_t
    real(wp), allocatable :: w(:)               !< (nf, -2:3, nv)
    real(wp), allocatable :: wl(:), wr(:)       !< (nf, 0:0, nv)
    real(wp), allocatable :: c2(:)              !< cells' c^2 (nb, 0:n+1): n + 2 <= 2 (n + 1)
    real(wp), allocatable :: rz(:), az(:), beta(:)   !< rho a, a^2, 4 G / (3 rho a^2): (nf)
    logical, allocatable :: ok(:)               !< faces with a reference sound speed (nf)
  end type characteristic_work_t

contains

  !> The variables code of a deck name (one of variables_names).
  integer function variables_from_name(name) result(code)
    character(len=*), intent(in) :: name
    code = choice_index(variables_names, name, 'variables_from_name')
  end function variables_from_name

  !> Workspace for bundles of up to nf faces of nv variables.
  subroutine characteristic_work_init(nf, nv, work)
    integer, intent(in) :: nf, nv
    type(characteristic_work_t), intent(out) :: work
    allocate(work%w(nf * 6 * nv), work%wl(nf * nv), work%wr(nf * nv), work%c2(2 * nf))
    allocate(work%rz(nf), work%az(nf), work%beta(nf), work%ok(nf))
  end subroutine characteristic_work_init

  !> Face states of nv variables on nb pencils of n cells (m_reconstruct's reconstruct_faces:
  !> pw(nb, 1-g:n+g, nv) primitives in the pencil frame -> left, right (nb, 0:n, nv)), in the
  !> given variables. solid: pencil place 6 is S_nn and shear the shear modulus.
  subroutine reconstruct_pencils(scheme, variables, eos, solid, shear, nb, n, g, nv, pw, &
      left, right, bounded_from, work)
    integer, intent(in) :: scheme, variables, nb, n, g, nv, bounded_from
    type(eos_t), intent(in) :: eos
    logical, intent(in) :: solid
    real(wp), intent(in) :: shear
    real(wp), intent(in) :: pw(nb, 1-g:n+g, nv)
    real(wp), intent(out) :: left(nb, 0:n, nv), right(nb, 0:n, nv)
    type(characteristic_work_t), intent(inout) :: work
    integer :: nf
    if (variables == variables_primitive .or. scheme == scheme_eno1) then
      call reconstruct_faces(scheme, nb, n, g, nv, pw, left, right, bounded_from)
      return
    end if
    nf = nb * (n + 1)
    call eos_sound_speed2(eos, nb * (n + 2), pw(:, 0:n+1, 1), pw(:, 0:n+1, 5), work%c2)
    call reference_states(nb, n, g, nv, solid, shear, pw, work%c2, work%rz, work%az, &
      work%beta, work%ok)
    call to_characteristic(nb, n, g, nv, solid, pw, work%rz, work%az, work%beta, work%w)
    call reconstruct_faces(scheme, nf, 0, 3, nv, work%w, work%wl, work%wr, bounded_from)
    call to_primitive(nf, nv, solid, work%wl, work%rz, work%az, work%beta, left)
    call to_primitive(nf, nv, solid, work%wr, work%rz, work%az, work%beta, right)
    if (.not. all(work%ok(1:nf))) call keep_primitive(scheme, nb, n, g, nv, pw, work%ok, &
      left, right, bounded_from)
  end subroutine reconstruct_pencils

  !> The frozen state of each face i + 1/2: the mean of cells i and i + 1 (rho, a^2; eq. 3.1).
  subroutine reference_states(nb, n, g, nv, solid, shear, pw, c2, rz, az, beta, ok)
    integer, intent(in) :: nb, n, g, nv
    logical, intent(in) :: solid
    real(wp), intent(in) :: shear, pw(nb, 1-g:n+g, nv), c2(nb, 0:n+1)
    real(wp), intent(out) :: rz(nb, 0:n), az(nb, 0:n), beta(nb, 0:n)
    logical, intent(out) :: ok(nb, 0:n)
    real(wp) :: rho, a2, elastic
    integer :: i, b
    do i = 0, n
      do b = 1, nb
        rho = 0.5_wp * (pw(b, i, 1) + pw(b, i + 1, 1))
        a2 = 0.5_wp * (c2(b, i) + c2(b, i + 1))
        elastic = 0.0_wp
        if (solid .and. rho > 0.0_wp) elastic = (4.0_wp / 3.0_wp) * shear / rho
        a2 = a2 + elastic
        ok(b, i) = rho > 0.0_wp .and. a2 > 0.0_wp .and. a2 < huge(1.0_wp)
        if (.not. ok(b, i)) then   ! any invertible basis: the face is redone in primitives
          rho = 1.0_wp
          a2 = 1.0_wp
        end if
        rz(b, i) = rho * sqrt(a2)
        az(b, i) = a2
        beta(b, i) = elastic / a2
      end do
    end do
  end subroutine reference_states

  !> w(f, k, :) = the characteristic variables of cell i + k in the basis of face f = (b, i),
  !> k = -2 .. 3 (eq. 3.2): with sigma = S_nn - p (S_nn = 0 for a gas)
  !>   place 1: rho + sigma / a^2          (entropy wave, speed u)
  !>   place 2: (u + sigma / (rho a)) / 2  (speed u - a)
  !>   place 5: (u - sigma / (rho a)) / 2  (speed u + a)
  !>   place 6: S_nn - beta sigma          (solid: the deviator's part at speed u)
  subroutine to_characteristic(nb, n, g, nv, solid, pw, rz, az, beta, w)
    integer, intent(in) :: nb, n, g, nv
    logical, intent(in) :: solid
    real(wp), intent(in) :: pw(nb, 1-g:n+g, nv)
    real(wp), intent(in) :: rz(nb, 0:n), az(nb, 0:n), beta(nb, 0:n)
    real(wp), intent(out) :: w(nb, 0:n, -2:3, nv)
    real(wp) :: sigma, s
    integer :: i, b, k, m
    do k = -2, 3
      do m = 1, nv
        if (m == 1 .or. m == 2 .or. m == 5 .or. (solid .and. m == 6)) cycle
        w(:, :, k, m) = pw(:, k:n+k, m)
      end do
      do i = 0, n
        do b = 1, nb
          s = 0.0_wp
          if (solid) s = pw(b, i + k, 6)
          sigma = s - pw(b, i + k, 5)
          w(b, i, k, 1) = pw(b, i + k, 1) + sigma / az(b, i)
          w(b, i, k, 2) = 0.5_wp * (pw(b, i + k, 2) + sigma / rz(b, i))
          w(b, i, k, 5) = 0.5_wp * (pw(b, i + k, 2) - sigma / rz(b, i))
          if (solid) w(b, i, k, 6) = s - beta(b, i) * sigma
        end do
      end do
    end do
  end subroutine to_characteristic

  !> The primitive face values of the characteristic ones wc(f, :) (eq. 3.3).
  subroutine to_primitive(nf, nv, solid, wc, rz, az, beta, v)
    integer, intent(in) :: nf, nv
    logical, intent(in) :: solid
    real(wp), intent(in) :: wc(nf, nv), rz(nf), az(nf), beta(nf)
    real(wp), intent(out) :: v(nf, nv)
    real(wp) :: sigma, s
    integer :: f, m
    do m = 1, nv
      if (m == 1 .or. m == 2 .or. m == 5 .or. (solid .and. m == 6)) cycle
      v(:, m) = wc(:, m)
    end do
    do f = 1, nf
      sigma = rz(f) * (wc(f, 2) - wc(f, 5))
      s = 0.0_wp
      if (solid) then
        s = wc(f, 6) + beta(f) * sigma
        v(f, 6) = s
      end if
      v(f, 1) = wc(f, 1) - sigma / az(f)
      v(f, 2) = wc(f, 2) + wc(f, 5)
      v(f, 5) = s - sigma
    end do
  end subroutine to_primitive

  !> The faces without a reference sound speed (not ok) take the primitive reconstruction.
  subroutine keep_primitive(scheme, nb, n, g, nv, pw, ok, left, right, bounded_from)
    integer, intent(in) :: scheme, nb, n, g, nv, bounded_from
    real(wp), intent(in) :: pw(nb, 1-g:n+g, nv)
    logical, intent(in) :: ok(nb, 0:n)
    real(wp), intent(inout) :: left(nb, 0:n, nv), right(nb, 0:n, nv)
    real(wp) :: pl(nb, 0:n, nv), pr(nb, 0:n, nv)
    integer :: m
    call reconstruct_faces(scheme, nb, n, g, nv, pw, pl, pr, bounded_from)
    do m = 1, nv
      where (.not. ok)
        left(:, :, m) = pl(:, :, m)
        right(:, :, m) = pr(:, :, m)
      end where
    end do
  end subroutine keep_primitive

end module m_characteristic
