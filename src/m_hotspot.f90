!> Hot-spot diagnostics (issue 16, manual/hotspots.md): at each history row, for each
!> temperature threshold (&output hot_thresholds, 700 K unless set), the area (2D) or volume
!> (3D, and axisymmetric) and the mass of the material above it and the number of distinct
!> hot spots (regions of face-connected cells above it); for each void body its volume from
!> its level set and the peak temperature within hot_reach of its starting radius of its
!> centre. The run's summary (run.json `hotspots`) keeps the peaks: the hottest cell and when,
!> the largest hot area and count per threshold, and per void its starting and least volume,
!> when it collapsed (its volume first below collapse_fraction of the start) and its peak
!> temperature near it.
!> The counting is the same on any number of ranks: each block lists its cells above the
!> lowest threshold (global index and temperature); the lists are joined in block-id order
!> on every rank (a sum of an array in which each entry has one non-zero term) and the
!> regions are counted there, by union-find over the sorted list. The blocks' sums (area,
!> mass, list length, peak near each void) travel together in one such sum by block id.
module m_hotspot
  use m_kinds, only: wp, i8, name_len
  use m_comm, only: comm_sum_array
  use m_json, only: json_t, json_object, json_close, json_put, json_put_array, &
    json_put_members
  use m_config, only: config_t, is_set, material_index
  use m_levelset_bodies, only: ls_set_t, ls_void
  use m_scene, only: made_t
  use m_text, only: int_text
  implicit none
  private
  public :: hot_t, hot_start, hot_setup, hot_columns, hot_row_start, hot_block, hot_cell, hot_row
  public :: hot_count, hot_nearest, hot_wants
  public :: hot_json, hot_pack, hot_unpack

  integer, parameter :: max_thresholds = 4
  !> a void has collapsed when its volume is below this share of its starting volume
  real(wp), parameter :: collapse_fraction = 0.01_wp
  !> the peak near a void: within this many of its starting radii of its centre
  real(wp), parameter :: hot_reach = 1.5_wp

  !> One void body: where it is, and what the run has seen of it.
  type :: void_t
    character(len=name_len) :: name = ''
    integer :: l = 0                      !< its level set
    real(wp) :: centre(3) = 0.0_wp, radius = 0.0_wp
    real(wp) :: vol0 = -1.0_wp            !< its volume at the first row (-1: not yet)
    real(wp) :: vol_min = huge(1.0_wp), t_min = 0.0_wp
    real(wp) :: t_collapse = -1.0_wp      !< -1: not collapsed
    real(wp) :: t_near_max = 0.0_wp, t_near_when = 0.0_wp
  end type void_t

  !> The thresholds, the voids, the block lists of one row and the run's peaks.
  type :: hot_t
    logical :: on = .false.               !< a material in use has a temperature
    integer :: ndim = 3                   !< distances to a void's centre along these
    integer :: n = 0                      !< thresholds
    real(wp) :: thr(max_thresholds) = 0.0_wp
    type(void_t), allocatable :: void(:)
    ! this row, on this rank: per block id its sums (area and mass per threshold, cells
    ! listed, peak near each void: table rows), and its cells above thr(1), block by block
    integer :: nblocks = 0
    real(wp), allocatable :: part(:, :)           !< (table row, block id)
    integer(i8), allocatable :: idx(:)            !< global cell index (0-based)
    real(wp), allocatable :: temp(:)
    integer, allocatable :: block_of(:)           !< block id of each listed cell
    integer :: nlist = 0
    integer :: id = 0                             !< the block hot_cell adds to
    integer, allocatable :: near(:)               !< the voids within reach of that block
    integer :: nnear = 0
    ! the run's peaks
    real(wp) :: t_peak = 0.0_wp, t_peak_time = 0.0_wp
    real(wp) :: area_max(max_thresholds) = 0.0_wp, area_when(max_thresholds) = 0.0_wp
    integer :: spots_max(max_thresholds) = 0
    real(wp) :: spots_when(max_thresholds) = 0.0_wp
  end type hot_t

contains

  !> The hot-spot diagnostics (m_hotspot): on when a material in use has a temperature (cv);
  !> the void bodies with their centres and sizes (a box's half diagonal, a half space none),
  !> each sphere of a random_spheres body on its own (name.k).
  subroutine hot_start(hot, cfg, made, ls, phase_material, ndim, nblocks)
    type(hot_t), intent(out) :: hot
    type(config_t), intent(in) :: cfg
    type(made_t), intent(in) :: made(:)
    type(ls_set_t), intent(in) :: ls
    character(len=*), intent(in) :: phase_material(:)
    integer, intent(in) :: ndim, nblocks
    integer :: l, k
    integer, allocatable :: lv(:), ls_of(:)
    real(wp), allocatable :: centres(:, :), radii(:)
    character(len=name_len), allocatable :: names(:)
    logical :: has_t
    has_t = .false.
    do k = 1, size(phase_material)
      has_t = has_t .or. is_set(cfg%materials(material_index(cfg, phase_material(k)))%cv)
    end do
    allocate(lv(0))
    if (ls%n > 0) lv = pack([(l, l = 1, ls%n)], ls%kind == ls_void)
    ! one entry per void body, but one per sphere of a random_spheres body (all on its level
    ! set: m_hotspot gives each cell to the nearest sphere)
    allocate(ls_of(0), names(0), centres(3, 0), radii(0))
    do k = 1, size(lv)
      associate (body => cfg%bodies(ls%body(lv(k))), m => made(ls%body(lv(k))))
        if (body%shape == 'random_spheres' .and. allocated(m%spheres)) then
          do l = 1, size(m%spheres, 2)
            call add(trim(body%name) // '.' // int_text(l), m%spheres(1:3, l), m%spheres(4, l))
          end do
        else if (any(body%shape == [character(len=name_len) :: 'box', 'random_field'])) then
          call add(body%name, 0.5_wp * (body%lo + body%hi), &
            0.5_wp * norm2(body%hi(1:ndim) - body%lo(1:ndim)))
        else
          call add(body%name, body%center, body%radius)
        end if
      end associate
    end do
    call hot_setup(hot, has_t, ndim, cfg%hot_thresholds, names, ls_of, centres, radii, nblocks)

  contains

    subroutine add(name, centre, radius)
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: centre(3), radius
      names = [character(len=name_len) :: names, name]
      ls_of = [ls_of, lv(k)]
      centres = reshape([centres, centre], [3, size(centres, 2) + 1])
      radii = [radii, radius]
    end subroutine add
  end subroutine hot_start

  !> thresholds: the deck's (K, ascending; those <= 0 left out); names, centres and radii of
  !> the void bodies with their level-set numbers; nblocks: the blocks of the grid.
  subroutine hot_setup(hot, on, ndim, thresholds, names, ls_index, centres, radii, nblocks)
    type(hot_t), intent(out) :: hot
    logical, intent(in) :: on
    integer, intent(in) :: ndim
    real(wp), intent(in) :: thresholds(:), centres(:, :), radii(:)
    character(len=*), intent(in) :: names(:)
    integer, intent(in) :: ls_index(:), nblocks
    integer :: v, k
    real(wp) :: t
    hot%on = on
    hot%ndim = ndim
    hot%n = min(count(thresholds > 0.0_wp), max_thresholds)
    hot%thr(1:hot%n) = pack(thresholds, thresholds > 0.0_wp)
    ! ascending (hot_cell counts a cell for each threshold up to the first it is below)
    do v = 2, hot%n
      do k = v, 2, -1
        if (.not. hot%thr(k) < hot%thr(k - 1)) exit
        t = hot%thr(k)
        hot%thr(k) = hot%thr(k - 1)
        hot%thr(k - 1) = t
      end do
    end do
    allocate(hot%void(size(names)))
    do v = 1, size(names)
      hot%void(v)%name = names(v)
      hot%void(v)%l = ls_index(v)
      hot%void(v)%centre = centres(:, v)
      hot%void(v)%radius = radii(v)
    end do
    hot%nblocks = nblocks
    allocate(hot%part(row_near(size(names)), nblocks), hot%near(size(names)))
    allocate(hot%idx(0), hot%temp(0), hot%block_of(0))
  end subroutine hot_setup

  !> The table row of a block's cells listed; row_count + v is void v's peak near it.
  pure integer function row_count()
    row_count = 2 * max_thresholds + 1
  end function row_count

  pure integer function row_near(v)
    integer, intent(in) :: v
    row_near = row_count() + v
  end function row_near

  !> history.csv's columns: per threshold hot_area_<T>, hot_mass_<T>, hot_spots_<T>; the
  !> ratio of internal to kinetic energy; per void <name>_vol and <name>_T_near.
  function hot_columns(hot) result(cols)
    type(hot_t), intent(in) :: hot
    character(len=name_len), allocatable :: cols(:)
    character(len=16) :: t
    integer :: m, v
    allocate(cols(0))
    if (.not. hot%on) return
    do m = 1, hot%n
      write(t, '(i0)') nint(hot%thr(m))
      cols = [character(len=name_len) :: cols, 'hot_area_' // trim(t), 'hot_mass_' // trim(t), &
        'hot_spots_' // trim(t)]
    end do
    cols = [character(len=name_len) :: cols, 'ie_over_ke']
    do v = 1, size(hot%void)
      cols = [character(len=name_len) :: cols, trim(hot%void(v)%name) // '_vol', &
        trim(hot%void(v)%name) // '_T_near']
    end do
  end function hot_columns

  !> The start of a history row: no sums, nothing listed yet.
  subroutine hot_row_start(hot)
    type(hot_t), intent(inout) :: hot
    hot%part = 0.0_wp
    hot%nlist = 0
  end subroutine hot_row_start

  !> The block hot_cell adds to next: its id and the box lo..hi its cells' centres span; the
  !> voids whose reach meets that box are the only ones its cells are measured against.
  subroutine hot_block(hot, id, lo, hi)
    type(hot_t), intent(inout) :: hot
    integer, intent(in) :: id
    real(wp), intent(in) :: lo(3), hi(3)
    real(wp) :: gap(3)
    integer :: v
    hot%id = id
    hot%nnear = 0
    do v = 1, size(hot%void)
      gap = max(lo - hot%void(v)%centre, 0.0_wp, hot%void(v)%centre - hi)
      if (norm2(gap(1:hot%ndim)) > hot_reach * hot%void(v)%radius) cycle
      hot%nnear = hot%nnear + 1
      hot%near(hot%nnear) = v
    end do
  end subroutine hot_block

  !> One real cell of the block (global cell gidx, centre x, volume dv, density rho) at
  !> temperature temp: its share of the sums, the list, and the voids' peaks near it.
  subroutine hot_cell(hot, gidx, x, dv, rho, temp)
    type(hot_t), intent(inout) :: hot
    integer(i8), intent(in) :: gidx
    real(wp), intent(in) :: x(3), dv, rho, temp
    integer :: m, k, v, id
    logical :: mine(hot%nnear)
    id = hot%id
    ! (voids on one level set, the spheres of one body: the cell is the nearest one's; no
    ! void near the block, as in every scene without voids: nothing to find)
    if (hot%nnear > 0) mine = hot_nearest(hot, x, hot%near(1:hot%nnear))
    do k = 1, hot%nnear
      v = hot%near(k)
      if (.not. mine(k)) cycle
      if (norm2(x(1:hot%ndim) - hot%void(v)%centre(1:hot%ndim)) > hot_reach &
        * hot%void(v)%radius) cycle
      hot%part(row_near(v), id) = max(hot%part(row_near(v), id), temp)
    end do
    if (hot%n == 0) return
    if (.not. temp > hot%thr(1)) return
    do m = 1, hot%n
      if (.not. temp > hot%thr(m)) exit
      hot%part(2 * m - 1, id) = hot%part(2 * m - 1, id) + dv
      hot%part(2 * m, id) = hot%part(2 * m, id) + dv * rho
    end do
    if (hot%nlist == size(hot%idx)) call grow()
    hot%nlist = hot%nlist + 1
    hot%idx(hot%nlist) = gidx
    hot%temp(hot%nlist) = temp
    hot%block_of(hot%nlist) = id
    hot%part(row_count(), id) = hot%part(row_count(), id) + 1.0_wp

  contains

    subroutine grow()
      integer(i8), allocatable :: i2(:)
      real(wp), allocatable :: t2(:)
      integer, allocatable :: b2(:)
      integer :: nn
      nn = max(64, 2 * size(hot%idx))
      allocate(i2(nn), t2(nn), b2(nn))
      i2(1:hot%nlist) = hot%idx(1:hot%nlist)
      t2(1:hot%nlist) = hot%temp(1:hot%nlist)
      b2(1:hot%nlist) = hot%block_of(1:hot%nlist)
      call move_alloc(i2, hot%idx)
      call move_alloc(t2, hot%temp)
      call move_alloc(b2, hot%block_of)
    end subroutine grow
  end subroutine hot_cell

  !> Whether hot_cell would count a cell at temperature temp of the block it adds to: a void
  !> is near the block, or temp is above the first threshold (the caller skips the rest).
  pure logical function hot_wants(hot, temp) result(wants)
    type(hot_t), intent(in) :: hot
    real(wp), intent(in) :: temp
    wants = hot%nnear > 0
    if (hot%n > 0) wants = wants .or. temp > hot%thr(1)
  end function hot_wants

  !> Which of the voids cand (ascending) is, of those on its level set, the one whose surface
  !> is nearest to x (the distance |x - centre| - radius; of equal ones the first): each cell
  !> near the spheres of one body belongs to one of them. A void alone on its level set
  !> always is. One pass over cand.
  pure function hot_nearest(hot, x, cand) result(mine)
    type(hot_t), intent(in) :: hot
    real(wp), intent(in) :: x(3)
    integer, intent(in) :: cand(:)
    logical :: mine(size(cand))
    real(wp) :: d(size(cand))
    integer, allocatable :: best(:)
    integer :: k, l
    allocate(best(maxval([0, hot%void(cand)%l])))
    best = 0
    do k = 1, size(cand)
      l = hot%void(cand(k))%l
      d(k) = norm2(x(1:hot%ndim) - hot%void(cand(k))%centre(1:hot%ndim)) &
        - hot%void(cand(k))%radius
      if (best(l) == 0) then
        best(l) = k
      else if (d(k) < d(best(l))) then
        best(l) = k
      end if
    end do
    mine = .false.
    do l = 1, size(best)
      if (best(l) > 0) mine(best(l)) = .true.
    end do
  end function hot_nearest

  !> The row's values (hot_columns' order) at time t, collective; void_vol: each void's
  !> volume (summed over the grid already), internal and kinetic: the grid's totals; cells:
  !> the grid's cells along each direction. Updates the run's peaks (t_max: the hottest cell).
  function hot_row(hot, t, t_max, internal, kinetic, void_vol, cells) result(v)
    type(hot_t), intent(inout) :: hot
    real(wp), intent(in) :: t, t_max, internal, kinetic, void_vol(:)
    integer, intent(in) :: cells(3)
    real(wp), allocatable :: v(:)
    real(wp), allocatable :: table(:, :), list(:, :)
    real(wp) :: sums(2 * max_thresholds), near(size(hot%void))
    integer :: first(hot%nblocks), seen(hot%nblocks)
    integer :: m, k, id, nv, spots
    allocate(v(0))
    if (.not. hot%on) return
    nv = size(hot%void)
    ! the blocks' sums by block id (each entry held by one rank: the same bits on any
    ! rank count), then over the blocks
    table = hot%part
    call sum_table(table)
    sums = sum(table(1:2 * max_thresholds, :), dim=2)
    near = maxval(table(row_near(1):row_near(nv), :), dim=2)
    ! the listed cells (index, temperature), joined in block-id order
    first(1) = 0
    do id = 2, hot%nblocks
      first(id) = first(id - 1) + nint(table(row_count(), id - 1))
    end do
    allocate(list(2, nint(sum(table(row_count(), :)))))
    list = 0.0_wp
    seen = 0
    do k = 1, hot%nlist
      id = hot%block_of(k)
      seen(id) = seen(id) + 1
      list(:, first(id) + seen(id)) = [real(hot%idx(k), wp), hot%temp(k)]
    end do
    call sum_table(list)
    do m = 1, hot%n
      spots = hot_count(nint(pack(list(1, :), list(2, :) > hot%thr(m)), i8), cells)
      v = [v, sums(2 * m - 1), sums(2 * m), real(spots, wp)]
      if (sums(2 * m - 1) > hot%area_max(m)) then
        hot%area_max(m) = sums(2 * m - 1)
        hot%area_when(m) = t
      end if
      if (spots > hot%spots_max(m)) then
        hot%spots_max(m) = spots
        hot%spots_when(m) = t
      end if
    end do
    ! (0 while nothing moves; merge would evaluate the quotient)
    if (kinetic > 0.0_wp) then
      v = [v, internal / kinetic]
    else
      v = [v, 0.0_wp]
    end if
    if (t_max > hot%t_peak) then
      hot%t_peak = t_max
      hot%t_peak_time = t
    end if
    do k = 1, nv
      associate (vd => hot%void(k))
        if (vd%vol0 < 0.0_wp) vd%vol0 = void_vol(k)
        if (void_vol(k) < vd%vol_min) then
          vd%vol_min = void_vol(k)
          vd%t_min = t
        end if
        if (vd%t_collapse < 0.0_wp .and. void_vol(k) < collapse_fraction * vd%vol0) &
          vd%t_collapse = t
        if (near(k) > vd%t_near_max) then
          vd%t_near_max = near(k)
          vd%t_near_when = t
        end if
        v = [v, void_vol(k), near(k)]
      end associate
    end do

  contains

    subroutine sum_table(a)
      real(wp), allocatable, intent(inout) :: a(:, :)
      real(wp), allocatable :: flat(:)
      flat = reshape(a, [size(a)])
      call comm_sum_array(flat)
      a = reshape(flat, shape(a))
    end subroutine sum_table
  end function hot_row

  !> run.json's `hotspots`: the thresholds, the run's peaks by threshold, and per void its
  !> volumes, collapse and peak nearby (times in s; -1: never).
  subroutine hot_json(hot, js)
    type(hot_t), intent(in) :: hot
    type(json_t), intent(inout) :: js
    integer :: v
    if (.not. hot%on) return
    call json_object(js, 'hotspots')
    call json_put(js, 'peak_T', hot%t_peak)
    call json_put(js, 'peak_T_time', hot%t_peak_time)
    call json_put_array(js, 'thresholds', hot%thr(1:hot%n))
    call json_put_array(js, 'area_max', hot%area_max(1:hot%n))
    call json_put_array(js, 'area_max_time', hot%area_when(1:hot%n))
    call json_put_array(js, 'spots_max', hot%spots_max(1:hot%n))
    call json_put_array(js, 'spots_max_time', hot%spots_when(1:hot%n))
    call json_put(js, 'collapse_fraction', collapse_fraction)
    call json_put(js, 'near_radii', hot_reach)
    do v = 1, size(hot%void)
      associate (vd => hot%void(v))
        call json_object(js, trim(vd%name))
        call json_put_members(js, [character(len=16) :: 'volume_start', 'volume_min', &
          'volume_min_time', 'collapse_time', 'peak_T_near', 'peak_T_near_time'], &
          [vd%vol0, vd%vol_min, vd%t_min, vd%t_collapse, vd%t_near_max, vd%t_near_when])
        call json_close(js)
      end associate
    end do
    call json_close(js)
  end subroutine hot_json

  !> The run's peaks as one array, for a checkpoint (hot_unpack reads it back): the peak and
  !> its time, per threshold (4) the largest area, its time, the most spots, their time, then
  !> per void its start and least volume, that time, collapse time, peak nearby and its time.
  function hot_pack(hot) result(a)
    type(hot_t), intent(in) :: hot
    real(wp), allocatable :: a(:)
    integer :: v
    a = [hot%t_peak, hot%t_peak_time, hot%area_max, hot%area_when, real(hot%spots_max, wp), &
      hot%spots_when]
    do v = 1, size(hot%void)
      associate (vd => hot%void(v))
        a = [a, vd%vol0, vd%vol_min, vd%t_min, vd%t_collapse, vd%t_near_max, vd%t_near_when]
      end associate
    end do
  end function hot_pack

  !> The peaks from hot_pack's array; ok: it had the length of this run's (the same voids).
  subroutine hot_unpack(hot, a, ok)
    type(hot_t), intent(inout) :: hot
    real(wp), intent(in) :: a(:)
    logical, intent(out) :: ok
    integer :: v, m, o
    ok = size(a) == 2 + 4 * max_thresholds + 6 * size(hot%void)
    if (.not. ok) return
    hot%t_peak = a(1)
    hot%t_peak_time = a(2)
    m = max_thresholds
    hot%area_max = a(3:2 + m)
    hot%area_when = a(3 + m:2 + 2 * m)
    hot%spots_max = nint(a(3 + 2 * m:2 + 3 * m))
    hot%spots_when = a(3 + 3 * m:2 + 4 * m)
    do v = 1, size(hot%void)
      o = 2 + 4 * m + 6 * (v - 1)
      associate (vd => hot%void(v))
        vd%vol0 = a(o + 1)
        vd%vol_min = a(o + 2)
        vd%t_min = a(o + 3)
        vd%t_collapse = a(o + 4)
        vd%t_near_max = a(o + 5)
        vd%t_near_when = a(o + 6)
      end associate
    end do
  end subroutine hot_unpack

  !> The number of regions of face-connected cells among the cells idx (0-based global
  !> indices i + n1 (j + n2 k), each listed once) of a grid of cells(3): union-find over the
  !> sorted list.
  integer function hot_count(idx, cells) result(regions)
    integer(i8), intent(in) :: idx(:)
    integer, intent(in) :: cells(3)
    integer(i8), allocatable :: s(:)
    integer, allocatable :: parent(:)
    integer(i8) :: stride(3), c(3), nb
    integer :: k, d, m, n
    n = size(idx)
    s = idx
    call sort(s)
    allocate(parent(n))
    parent = [(k, k = 1, n)]
    stride = [1_i8, int(cells(1), i8), int(cells(1), i8) * int(cells(2), i8)]
    do k = 1, n
      c(1) = mod(s(k), stride(2))
      c(2) = mod(s(k) / stride(2), int(cells(2), i8))
      c(3) = s(k) / stride(3)
      ! the neighbours above along each direction (those below find this cell)
      do d = 1, 3
        if (c(d) + 1 >= cells(d)) cycle
        nb = s(k) + stride(d)
        m = find_index(nb)
        if (m > 0) call join(k, m)
      end do
    end do
    regions = count([(root(k) == k, k = 1, n)])

  contains

    integer function find_index(key) result(pos)
      integer(i8), intent(in) :: key
      integer :: lo, hi, mid
      lo = 1
      hi = n
      pos = 0
      do while (lo <= hi)
        mid = (lo + hi) / 2
        if (s(mid) == key) then
          pos = mid
          return
        else if (s(mid) < key) then
          lo = mid + 1
        else
          hi = mid - 1
        end if
      end do
    end function find_index

    recursive integer function root(a) result(r)
      integer, intent(in) :: a
      if (parent(a) == a) then
        r = a
      else
        r = root(parent(a))
        parent(a) = r
      end if
    end function root

    subroutine join(a, b)
      integer, intent(in) :: a, b
      integer :: ra, rb
      ra = root(a)
      rb = root(b)
      if (ra /= rb) parent(max(ra, rb)) = min(ra, rb)
    end subroutine join
  end function hot_count

  !> Heap sort of integer keys, ascending.
  subroutine sort(a)
    integer(i8), intent(inout) :: a(:)
    integer :: n, k, last
    integer(i8) :: t
    n = size(a)
    do k = n / 2, 1, -1
      call sift(k, n)
    end do
    do last = n, 2, -1
      t = a(1)
      a(1) = a(last)
      a(last) = t
      call sift(1, last - 1)
    end do

  contains

    subroutine sift(start, bottom)
      integer, intent(in) :: start, bottom
      integer :: r, child
      r = start
      do while (2 * r <= bottom)
        child = 2 * r
        if (child < bottom) then
          if (a(child + 1) > a(child)) child = child + 1
        end if
        if (.not. a(child) > a(r)) return
        t = a(r)
        a(r) = a(child)
        a(child) = t
        r = child
      end do
    end subroutine sift
  end subroutine sort

end module m_hotspot
