!> C API, recovery on a caller's mesh: `sprc_recovery` holds the result of
!> `recover_on_mesh` (sprc_recovery_caller_mesh) for a mesh given as C arrays.
!>
!> C arrays in row-major order are the Fortran column-major arrays with the
!> same memory (`nodes[nnode][dim]` is `nodes(dim, nnode)`), so the real
!> arrays are used in place; the 0-based indices (connectivity, facet nodes,
!> point elements) are range-checked here and copied 1-based. The library
!> names entries in C notation (`c_indices`), so that every message names the
!> index as the C caller wrote it.
module sprc_capi_recovery
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_null_ptr, c_associated, c_f_pointer, c_loc
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_out_of_memory
   use sprc_core_alloc, only: check_allocation
   use sprc_core_material, only: voigt_size
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval, coded_degree, &
      & mesh_reference_unit, mesh_reference_symmetric
   use sprc_recovery_caller_mesh_check, only: method_code_type, decode_method
   use sprc_recovery_caller_mesh_element, only: element_known, element_nodes, element_facet_nodes, element_name
   use sprc_capi_error, only: capi_error_type, get_capi_error, set_capi_error
   implicit none
   private

   public :: capi_recovery_type, mesh_sizes_type, check_sizes, check_pointers, one_based
   public :: sprc_recover, sprc_recover_xi, sprc_recover_reference, sprc_get_recovery_nodal_stress, &
      & sprc_get_recovery_element_error, &
      & sprc_get_recovery_global_error, sprc_get_recovery_eta, sprc_eval_recovery, sprc_delete_recovery

   !> What an `sprc_recovery` handle points to.
   type :: capi_recovery_type
      type(mesh_recovery_type) :: result
   end type capi_recovery_type

   !> Sizes and codes of one `sprc_recover` call, checked before any array is touched.
   type :: mesh_sizes_type
      integer :: dim, analysis, nnode, element_type, nen, nelem, ngp, nstress, nfacet, facet_nnode
   end type mesh_sizes_type

contains

   !> Recover the stresses of a caller's mesh and estimate the error; returns
   !> a new recovery, or NULL with the error set (sprc.h documents the arrays).
   function sprc_recover(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction) result(rech) bind(C, name='sprc_recover')
      type(c_ptr), value :: errh
      integer(c_int), value :: dim, analysis, nnode, element_type, nen, nelem, ngp
      type(c_ptr), value :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress
      real(c_double), value :: young, poisson
      integer(c_int), value :: method, nfacet, facet_nnode
      type(c_ptr), value :: body_force, facet_nodes, facet_kind, facet_traction
      type(c_ptr) :: rech

      rech = recover_c(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, c_null_ptr, int(mesh_reference_unit, c_int))
   end function sprc_recover

   !> `sprc_recover` with the reference coordinates of the points (gauss_xi [nelem][ngp][dim],
   !> or NULL to derive them): checked instead of derived by Newton's method.
   function sprc_recover_xi(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi) result(rech) bind(C, name='sprc_recover_xi')
      type(c_ptr), value :: errh
      integer(c_int), value :: dim, analysis, nnode, element_type, nen, nelem, ngp
      type(c_ptr), value :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress
      real(c_double), value :: young, poisson
      integer(c_int), value :: method, nfacet, facet_nnode
      type(c_ptr), value :: body_force, facet_nodes, facet_kind, facet_traction, gauss_xi
      type(c_ptr) :: rech

      rech = recover_c(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi, int(mesh_reference_unit, c_int))
   end function sprc_recover_xi

   !> `sprc_recover_xi` with the convention of gauss_xi: SPRC_REFERENCE_UNIT (quads and
   !> hexes on [0, 1]^dim, as sprc_recover_xi) or SPRC_REFERENCE_SYMMETRIC ([-1, 1]^dim).
   function sprc_recover_reference(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi, reference) result(rech) &
         & bind(C, name='sprc_recover_reference')
      type(c_ptr), value :: errh
      integer(c_int), value :: dim, analysis, nnode, element_type, nen, nelem, ngp
      type(c_ptr), value :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress
      real(c_double), value :: young, poisson
      integer(c_int), value :: method, nfacet, facet_nnode
      type(c_ptr), value :: body_force, facet_nodes, facet_kind, facet_traction, gauss_xi
      integer(c_int), value :: reference
      type(c_ptr) :: rech

      rech = recover_c(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi, reference)
   end function sprc_recover_reference

   !> The one implementation of the entries (gauss_xi may be NULL).
   function recover_c(errh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, ngp, &
         & gauss_points, gauss_weights, gauss_stress, young, poisson, method, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi, reference) result(rech)
      integer(c_int), value :: reference
      type(c_ptr), value :: errh
      integer(c_int), value :: dim, analysis, nnode, element_type, nen, nelem, ngp
      type(c_ptr), value :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress
      real(c_double), value :: young, poisson
      integer(c_int), value :: method, nfacet, facet_nnode
      type(c_ptr), value :: body_force, facet_nodes, facet_kind, facet_traction, gauss_xi
      type(c_ptr) :: rech
      character(len=*), parameter :: entry = 'sprc_recover'
      real(c_double), pointer, contiguous :: gxi(:, :, :)
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec
      type(mesh_sizes_type) :: sz
      type(error_type), allocatable :: error
      real(c_double), pointer, contiguous :: x(:, :), gp(:, :, :), gw(:, :), gs(:, :, :), bf_ptr(:), ft_ptr(:, :)
      real(wp), allocatable :: bf(:), ft(:, :)
      integer(c_int), pointer :: conn_c(:, :), fn_c(:, :), fk_c(:)
      integer, allocatable :: conn(:, :), fn(:, :), fk(:)
      type(method_code_type) :: code
      integer :: stat

      rech = c_null_ptr
      if (.not. get_capi_error(errh, err)) return
      sz = mesh_sizes_type(dim, analysis, nnode, element_type, nen, nelem, ngp, voigt_size(analysis), nfacet, &
         & facet_nnode)
      call check_sizes(sz, error)
      if (.not. allocated(error)) call decode_method('sprc_recover', int(method), .false., code, error)
      if (.not. allocated(error) .and. reference /= mesh_reference_unit .and. reference /= mesh_reference_symmetric) &
         & call fail(error, 'sprc_recover: reference = '//itoa(reference)//' is not SPRC_REFERENCE_UNIT ('// &
         & itoa(mesh_reference_unit)//') or SPRC_REFERENCE_SYMMETRIC ('//itoa(mesh_reference_symmetric)//')')
      if (.not. allocated(error)) call check_pointers(sz, nodes, connectivity, gauss_points, gauss_weights, &
         & gauss_stress, facet_nodes, facet_kind, error)
      if (allocated(error)) then
         call set_capi_error(err, error)
         return
      end if
      call c_f_pointer(nodes, x, [dim, nnode])
      call c_f_pointer(connectivity, conn_c, [nen, nelem])
      call c_f_pointer(gauss_points, gp, [dim, ngp, nelem])
      call c_f_pointer(gauss_weights, gw, [ngp, nelem])
      call c_f_pointer(gauss_stress, gs, [sz%nstress, ngp, nelem])
      call one_based(conn_c, nnode, 'connectivity', conn, error)
      if (allocated(error)) then
         call set_capi_error(err, error)
         return
      end if
      if (c_associated(body_force)) then
         call c_f_pointer(body_force, bf_ptr, [dim])
         bf = bf_ptr
      end if
      if (nfacet > 0) then
         call c_f_pointer(facet_nodes, fn_c, [facet_nnode, nfacet])
         call c_f_pointer(facet_kind, fk_c, [nfacet])
         call one_based(fn_c, nnode, 'facet_nodes', fn, error)
         if (allocated(error)) then
            call set_capi_error(err, error)
            return
         end if
         allocate (fk(nfacet), stat=stat)
         call check_allocation(stat, 'sprc_recover', 'a copy of facet_kind', nfacet, 4, error)
         if (.not. allocated(error) .and. c_associated(facet_traction)) then
            allocate (ft(dim, nfacet), stat=stat)
            call check_allocation(stat, 'sprc_recover', 'a copy of facet_traction', nfacet, 8*dim, error)
         end if
         if (allocated(error)) then
            call set_capi_error(err, error)
            return
         end if
         fk(:) = int(fk_c)
         if (c_associated(facet_traction)) then
            call c_f_pointer(facet_traction, ft_ptr, [dim, nfacet])
            ft(:, :) = ft_ptr
         end if
      end if

      allocate (rec, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message=entry//': cannot allocate the recovery', stat=stat_out_of_memory)
         return
      end if
      ! Unallocated bf, fn, fk, ft reach the optional dummies as absent (F2008).
      if (c_associated(gauss_xi)) then
         call c_f_pointer(gauss_xi, gxi, [dim, ngp, nelem])
         call recover_on_mesh(dim, analysis, x, element_type, conn, gp, gw, gs, young, poisson, &
            & code%method, rec%result, error, body_force=bf, facet_nodes=fn, facet_kind=fk, &
            & facet_traction=ft, degree=coded_degree(code, int(element_type)), c_indices=.true., gauss_xi=gxi, &
            & reference=int(reference))
      else
         call recover_on_mesh(dim, analysis, x, element_type, conn, gp, gw, gs, young, poisson, &
            & code%method, rec%result, error, body_force=bf, facet_nodes=fn, facet_kind=fk, &
            & facet_traction=ft, degree=coded_degree(code, int(element_type)), c_indices=.true.)
      end if
      if (allocated(error)) then
         deallocate (rec)
         call set_capi_error(err, error)
         return
      end if
      rech = c_loc(rec)
   end function recover_c

   !> Counts and codes the array shapes depend on (the library checks the rest).
   subroutine check_sizes(sz, error)
      type(mesh_sizes_type), intent(in) :: sz
      type(error_type), allocatable, intent(out) :: error

      if (sz%dim /= 2 .and. sz%dim /= 3) then
         call fail(error, 'sprc_recover: dim = '//itoa(sz%dim)//' is not 2 or 3')
      else if (sz%nstress == 0) then
         call fail(error, 'sprc_recover: analysis = '//itoa(sz%analysis)// &
            & ' is not SPRC_PLANE_STRESS (1), SPRC_PLANE_STRAIN (2) or SPRC_SOLID (3)')
      else if (.not. element_known(sz%element_type)) then
         call fail(error, 'sprc_recover: element_type = '//itoa(sz%element_type)//' is unknown (SPRC_TRI3 = 5, '// &
            & 'SPRC_QUAD4 = 9, SPRC_TET4 = 10, SPRC_HEX8 = 12, SPRC_QUAD9 = 28, SPRC_HEX27 = 29)')
      else if (sz%nen /= element_nodes(sz%element_type)) then
         call fail(error, 'sprc_recover: nen = '//itoa(sz%nen)//' but a '//element_name(sz%element_type)// &
            & ' element has '//itoa(element_nodes(sz%element_type))//' nodes')
      else if (sz%nnode < 1 .or. sz%nelem < 1 .or. sz%ngp < 1) then
         call fail(error, 'sprc_recover: nnode = '//itoa(sz%nnode)//', nelem = '//itoa(sz%nelem)//', ngp = '// &
            & itoa(sz%ngp)//'; each must be >= 1')
      else if (sz%nfacet < 0) then
         call fail(error, 'sprc_recover: nfacet = '//itoa(sz%nfacet)//' is negative')
      else if (sz%nfacet > 0 .and. sz%facet_nnode /= element_facet_nodes(sz%element_type)) then
         call fail(error, 'sprc_recover: facet_nnode = '//itoa(sz%facet_nnode)//' but a facet of '// &
            & element_name(sz%element_type)//' has '//itoa(element_facet_nodes(sz%element_type))//' nodes')
      end if
   end subroutine check_sizes

   !> The arrays that must be given (body force and facet tractions may be NULL).
   subroutine check_pointers(sz, nodes, connectivity, gauss_points, gauss_weights, gauss_stress, facet_nodes, &
         & facet_kind, error)
      type(mesh_sizes_type), intent(in) :: sz
      type(c_ptr), intent(in) :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress, facet_nodes, &
         & facet_kind
      type(error_type), allocatable, intent(out) :: error

      if (.not. c_associated(nodes)) then
         call fail(error, 'sprc_recover: nodes is NULL')
      else if (.not. c_associated(connectivity)) then
         call fail(error, 'sprc_recover: connectivity is NULL')
      else if (.not. c_associated(gauss_points)) then
         call fail(error, 'sprc_recover: gauss_points is NULL')
      else if (.not. c_associated(gauss_weights)) then
         call fail(error, 'sprc_recover: gauss_weights is NULL')
      else if (.not. c_associated(gauss_stress)) then
         call fail(error, 'sprc_recover: gauss_stress is NULL')
      else if (sz%nfacet > 0 .and. .not. (c_associated(facet_nodes) .and. c_associated(facet_kind))) then
         call fail(error, 'sprc_recover: nfacet = '//itoa(sz%nfacet)//' but facet_nodes or facet_kind is NULL')
      end if
   end subroutine check_pointers

   !> 0-based node indices idx(nper, n) (C: [n][nper]) as 1-based, each in 0..nnode-1.
   subroutine one_based(idx, nnode, what, out, error)
      integer(c_int), intent(in) :: idx(:, :)
      integer, intent(in) :: nnode
      character(len=*), intent(in) :: what
      integer, allocatable, intent(out) :: out(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: a, e, stat

      do e = 1, size(idx, 2)
         do a = 1, size(idx, 1)
            if (idx(a, e) < 0 .or. idx(a, e) >= nnode) then
               call fail(error, 'sprc_recover: '//what//'['//itoa(e - 1)//']['//itoa(a - 1)//'] = '// &
                  & itoa(idx(a, e))//' is not a node in 0..'//itoa(nnode - 1))
               return
            end if
         end do
      end do
      allocate (out(size(idx, 1), size(idx, 2)), stat=stat)
      call check_allocation(stat, 'sprc_recover', 'a 1-based copy of '//what, size(idx), 4, error)
      if (allocated(error)) return
      out(:, :) = int(idx) + 1
   end subroutine one_based

   !> Recovered nodal stresses into out[n][nstress]; n must be the node count.
   subroutine sprc_get_recovery_nodal_stress(errh, rech, out, n) bind(C, name='sprc_get_recovery_nodal_stress')
      type(c_ptr), value :: errh, rech, out
      integer(c_int), value :: n
      character(len=*), parameter :: entry = 'sprc_get_recovery_nodal_stress'
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec
      real(c_double), pointer :: values(:, :)

      if (.not. get_handles(errh, rech, entry, err, rec)) return
      if (.not. check_out(err, out, n, rec%result%nnode, entry, 'nnode')) return
      call c_f_pointer(out, values, [rec%result%nstress, n])
      values = rec%result%nodal
   end subroutine sprc_get_recovery_nodal_stress

   !> ZZ error per element into out[nelem]; nelem must be the element count.
   subroutine sprc_get_recovery_element_error(errh, rech, out, nelem) bind(C, name='sprc_get_recovery_element_error')
      type(c_ptr), value :: errh, rech, out
      integer(c_int), value :: nelem
      character(len=*), parameter :: entry = 'sprc_get_recovery_element_error'
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec
      real(c_double), pointer :: values(:)

      if (.not. get_handles(errh, rech, entry, err, rec)) return
      if (.not. check_out(err, out, nelem, rec%result%nelem, entry, 'nelem')) return
      call c_f_pointer(out, values, [nelem])
      values = rec%result%elem_err
   end subroutine sprc_get_recovery_element_error

   !> Global ZZ estimate ||sigma* - sigma_h|| (energy norm); NaN on error.
   function sprc_get_recovery_global_error(errh, rech) result(x) bind(C, name='sprc_get_recovery_global_error')
      type(c_ptr), value :: errh, rech
      real(c_double) :: x
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec

      x = ieee_value(x, ieee_quiet_nan)
      if (.not. get_handles(errh, rech, 'sprc_get_recovery_global_error', err, rec)) return
      x = rec%result%err
   end function sprc_get_recovery_global_error

   !> Estimated relative error err / sqrt(||sigma_h||^2 + err^2); NaN on error.
   function sprc_get_recovery_eta(errh, rech) result(x) bind(C, name='sprc_get_recovery_eta')
      type(c_ptr), value :: errh, rech
      real(c_double) :: x
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec

      x = ieee_value(x, ieee_quiet_nan)
      if (.not. get_handles(errh, rech, 'sprc_get_recovery_eta', err, rec)) return
      x = rec%result%eta
   end function sprc_get_recovery_eta

   !> The recovered field at points[npts][dim] into stress[npts][nstress]; elements[npts]
   !> (0-based, -1: search) or NULL (search every point). On error stress is unspecified.
   subroutine sprc_eval_recovery(errh, rech, npts, points, elements, stress) bind(C, name='sprc_eval_recovery')
      type(c_ptr), value :: errh, rech
      integer(c_int), value :: npts
      type(c_ptr), value :: points, elements, stress
      character(len=*), parameter :: entry = 'sprc_eval_recovery'
      type(capi_error_type), pointer :: err
      type(capi_recovery_type), pointer :: rec
      type(error_type), allocatable :: error
      real(c_double), pointer :: x(:, :), sigma(:, :)
      integer(c_int), pointer :: elem_c(:)
      integer, allocatable :: elem(:)
      integer :: i, nelem, stat

      if (.not. get_handles(errh, rech, entry, err, rec)) return
      if (npts < 0) then
         call set_capi_error(err, message=entry//': npts = '//itoa(npts)//' is negative', stat=stat_invalid_input)
         return
      end if
      if (npts == 0) return
      if (.not. (c_associated(points) .and. c_associated(stress))) then
         call set_capi_error(err, message=entry//': points or stress is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(points, x, [rec%result%dim, npts])
      call c_f_pointer(stress, sigma, [rec%result%nstress, npts])
      if (c_associated(elements)) then
         nelem = rec%result%nelem
         call c_f_pointer(elements, elem_c, [npts])
         do i = 1, npts
            if (elem_c(i) < -1 .or. elem_c(i) >= nelem) then
               call set_capi_error(err, message=entry//': elements['//itoa(i - 1)//'] = '//itoa(elem_c(i))// &
                  & ' is not -1 (search) or an element in 0..'//itoa(nelem - 1), stat=stat_invalid_input)
               return
            end if
         end do
         ! 0-based with -1 = search is the library's 1-based with 0 = search.
         allocate (elem(npts), stat=stat)
         call check_allocation(stat, entry, 'a 1-based copy of elements', npts, 4, error)
         if (allocated(error)) then
            call set_capi_error(err, error)
            return
         end if
         elem(:) = int(elem_c) + 1
         call mesh_recovery_eval(rec%result, x, sigma, error, elem)
      else
         call mesh_recovery_eval(rec%result, x, sigma, error)
      end if
      if (allocated(error)) call set_capi_error(err, error)
   end subroutine sprc_eval_recovery

   !> Free the recovery `*ptr` and set it to NULL; NULL `ptr` or `*ptr` is a no-op.
   subroutine sprc_delete_recovery(ptr) bind(C, name='sprc_delete_recovery')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_recovery_type), pointer :: rec

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, rec)
      deallocate (rec)
      handle = c_null_ptr
   end subroutine sprc_delete_recovery

   !> The objects behind an error and a recovery handle; false (the NULL
   !> recovery reported, naming the entry) when either is NULL.
   logical function get_handles(errh, rech, entry, err, rec) result(ok)
      type(c_ptr), intent(in) :: errh, rech
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(capi_recovery_type), pointer, intent(out) :: rec

      rec => null()
      ok = get_capi_error(errh, err)
      if (.not. ok) return
      ok = c_associated(rech)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the recovery handle is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(rech, rec)
   end function get_handles

   !> An output array of n rows where `want` are needed, and not NULL.
   logical function check_out(err, out, n, want, entry, what) result(ok)
      type(capi_error_type), intent(inout) :: err
      type(c_ptr), intent(in) :: out
      integer, intent(in) :: n, want
      character(len=*), intent(in) :: entry, what

      ok = .false.
      if (n /= want) then
         call set_capi_error(err, message=entry//': n = '//itoa(n)//' but the recovery has '//what//' = '// &
            & itoa(want)//' (n must equal it)', stat=stat_invalid_input)
      else if (.not. c_associated(out)) then
         call set_capi_error(err, message=entry//': out is NULL', stat=stat_invalid_input)
      else
         ok = .true.
      end if
   end function check_out

   pure subroutine fail(error, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      call fatal_error(error, message, stat_invalid_input)
   end subroutine fail

end module sprc_capi_recovery
