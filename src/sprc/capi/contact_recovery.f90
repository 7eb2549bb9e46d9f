!> C API, contact recovery on a caller's meshes: an `sprc_contact_input` collects bodies
!> (`sprc_contact_add_body`, the arguments of sprc_recover_reference) and pairs
!> (`sprc_contact_add_pair`), `sprc_recover_contact` runs recover_contact_on_mesh
!> (sprc_contact_caller_mesh_recovery) into an `sprc_contact_recovery`, whose bodies are read as
!> ordinary recoveries (`sprc_get_contact_body`: a copy, an `sprc_recovery`) and whose pairs
!> by `sprc_get_contact_pair`.
!>
!> The real arrays of a body (and a pair's slip directions and pressure) are used in place
!> (C row-major = Fortran column-major, no copy): they must stay valid until
!> sprc_recover_contact returns. Index arrays are range-checked when added and kept as
!> 1-based copies. Messages name entries in C notation.
module sprc_capi_contact_recovery
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_null_ptr, c_associated, c_f_pointer, c_loc
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_out_of_memory
   use sprc_core_material, only: voigt_size
   use sprc_recovery_caller_mesh, only: mesh_reference_unit, mesh_reference_symmetric
   use sprc_recovery_caller_mesh_check, only: method_code_type, decode_method
   use sprc_recovery_caller_mesh_element, only: element_facet_nodes, facet_npoints
   use sprc_contact_caller_mesh_recovery, only: contact_body_type, contact_pair_type, mesh_contact_recovery_type, &
      & recover_contact_on_mesh
   use sprc_capi_error, only: capi_error_type, get_capi_error, set_capi_error
   use sprc_capi_recovery, only: capi_recovery_type, mesh_sizes_type, check_sizes, check_pointers, one_based
   implicit none
   private

   public :: sprc_new_contact_input, sprc_contact_add_body, sprc_contact_add_pair, sprc_recover_contact, &
      & sprc_get_contact_body, sprc_get_contact_points, sprc_get_contact_pair, sprc_delete_contact_input, &
      & sprc_delete_contact_recovery

   !> What an `sprc_contact_input` points to: the bodies and pairs added so far.
   type :: capi_contact_input_type
      type(contact_body_type), allocatable :: bodies(:)
      type(contact_pair_type), allocatable :: pairs(:)
      integer :: nbody = 0, npair = 0
   end type capi_contact_input_type

   type :: capi_contact_recovery_type
      type(mesh_contact_recovery_type) :: result
   end type capi_contact_recovery_type

contains

   !> A new, empty contact input; NULL with the error set if out of memory.
   function sprc_new_contact_input(errh) result(inh) bind(C, name='sprc_new_contact_input')
      type(c_ptr), value :: errh
      type(c_ptr) :: inh
      type(capi_error_type), pointer :: err
      type(capi_contact_input_type), pointer :: in
      integer :: stat

      inh = c_null_ptr
      if (.not. get_capi_error(errh, err)) return
      allocate (in, stat=stat)
      if (stat == 0) allocate (in%bodies(4), in%pairs(4), stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_new_contact_input: out of memory', stat=stat_out_of_memory)
         return
      end if
      inh = c_loc(in)
   end function sprc_new_contact_input

   !> Add a body (the arguments of sprc_recover_reference; gauss_xi, body_force and the
   !> facets may be NULL). Returns its index (0-based), -1 on error.
   function sprc_contact_add_body(errh, inh, dim, analysis, nnode, nodes, element_type, nen, nelem, connectivity, &
         & ngp, gauss_points, gauss_weights, gauss_stress, young, poisson, body_force, nfacet, facet_nnode, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi, reference) result(index) &
         & bind(C, name='sprc_contact_add_body')
      type(c_ptr), value :: errh, inh
      integer(c_int), value :: dim, analysis, nnode, element_type, nen, nelem, ngp, nfacet, facet_nnode, reference
      type(c_ptr), value :: nodes, connectivity, gauss_points, gauss_weights, gauss_stress, body_force, &
         & facet_nodes, facet_kind, facet_traction, gauss_xi
      real(c_double), value :: young, poisson
      integer(c_int) :: index
      character(len=*), parameter :: entry = 'sprc_contact_add_body'
      type(capi_error_type), pointer :: err
      type(capi_contact_input_type), pointer :: in
      type(error_type), allocatable :: error
      type(contact_body_type) :: b
      integer(c_int), pointer :: ip(:, :), kp(:)
      integer, allocatable :: tmp(:, :)

      index = -1
      if (.not. get_input(errh, inh, entry, err, in)) return
      call check_sizes(mesh_sizes_type(dim, analysis, nnode, element_type, nen, nelem, ngp, voigt_size(analysis), &
         & nfacet, facet_nnode), error)
      if (.not. allocated(error)) call check_pointers(mesh_sizes_type(dim, analysis, nnode, element_type, nen, nelem, &
         & ngp, voigt_size(analysis), nfacet, facet_nnode), nodes, connectivity, gauss_points, gauss_weights, &
         & gauss_stress, facet_nodes, facet_kind, error)
      if (.not. allocated(error) .and. reference /= mesh_reference_unit .and. reference /= mesh_reference_symmetric) &
         & call fatal_error(error, 'sprc_recover: reference = '//itoa(reference)//' is not SPRC_REFERENCE_UNIT (0) '// &
         & 'or SPRC_REFERENCE_SYMMETRIC (1)', stat_invalid_input)
      if (.not. allocated(error)) then
         b%dim = dim
         b%analysis = analysis
         b%element_type = element_type
         b%young = young
         b%poisson = poisson
         b%reference = reference
         call c_f_pointer(nodes, b%nodes, [dim, nnode])
         call c_f_pointer(gauss_points, b%gp, [dim, ngp, nelem])
         call c_f_pointer(gauss_weights, b%gw, [ngp, nelem])
         call c_f_pointer(gauss_stress, b%gs, [voigt_size(analysis), ngp, nelem])
         if (c_associated(body_force)) call c_f_pointer(body_force, b%body_force, [dim])
         if (c_associated(gauss_xi)) call c_f_pointer(gauss_xi, b%gauss_xi, [dim, ngp, nelem])
         call c_f_pointer(connectivity, ip, [nen, nelem])
         call one_based(ip, nnode, 'connectivity', tmp, error)
      end if
      if (.not. allocated(error)) then
         allocate (b%connectivity(nen, nelem))
         b%connectivity = tmp
         if (nfacet > 0) then
            call c_f_pointer(facet_nodes, ip, [facet_nnode, nfacet])
            call one_based(ip, nnode, 'facet_nodes', tmp, error)
            if (.not. allocated(error)) then
               allocate (b%facet_nodes(facet_nnode, nfacet), b%facet_kind(nfacet))
               b%facet_nodes = tmp
               call c_f_pointer(facet_kind, kp, [nfacet])
               b%facet_kind = int(kp)
               if (c_associated(facet_traction)) call c_f_pointer(facet_traction, b%facet_traction, [dim, nfacet])
            end if
         end if
      end if
      if (allocated(error)) then
         call free_body(b)
         error%message = entry//': bodies['//itoa(in%nbody)//']'//error%message(len('sprc_recover') + 1:)
         call set_capi_error(err, error)
         return
      end if
      if (in%nbody == size(in%bodies)) call grow_bodies(in)
      in%nbody = in%nbody + 1
      in%bodies(in%nbody) = b
      index = in%nbody - 1
   end function sprc_contact_add_body

   !> Add a pair: slave and master bodies (0-based), the contact facets of each
   !> ([n][facet_nnode], 0-based nodes of that body) with their laws ([n], SPRC_CONTACT_*),
   !> mu (>= 0), the slip directions ([n][dim] or NULL) and the FE pressure at the slave
   !> points (or NULL). Returns the pair's index (0-based), -1 on error.
   function sprc_contact_add_pair(errh, inh, slave, master, nslave, slave_facets, slave_law, slave_slip, nmaster, &
         & master_facets, master_law, master_slip, mu, pressure) result(index) bind(C, name='sprc_contact_add_pair')
      type(c_ptr), value :: errh, inh
      integer(c_int), value :: slave, master, nslave, nmaster
      type(c_ptr), value :: slave_facets, slave_law, slave_slip, master_facets, master_law, master_slip, pressure
      real(c_double), value :: mu
      integer(c_int) :: index
      character(len=*), parameter :: entry = 'sprc_contact_add_pair'
      type(capi_error_type), pointer :: err
      type(capi_contact_input_type), pointer :: in
      type(error_type), allocatable :: error
      type(contact_pair_type) :: p
      character(len=:), allocatable :: pname

      index = -1
      if (.not. get_input(errh, inh, entry, err, in)) return
      pname = entry//': pairs['//itoa(in%npair)//']'
      if (slave < 0 .or. slave >= in%nbody) then
         call fail('.slave = '//itoa(slave)//' is not a body added (0..'//itoa(in%nbody - 1)//')')
      else if (master < 0 .or. master >= in%nbody) then
         call fail('.master = '//itoa(master)//' is not a body added (0..'//itoa(in%nbody - 1)//')')
      else if (.not. (mu >= 0.0_wp .and. mu <= huge(1.0_wp))) then
         call fail('.mu must be finite and >= 0')
      end if
      if (allocated(error)) then
         call set_capi_error(err, error)
         return
      end if
      p%slave = slave + 1
      p%master = master + 1
      p%mu = mu
      call side(.true., in%bodies(p%slave), nslave, slave_facets, slave_law, slave_slip, p%slave_facets, &
         & p%slave_law, p%slave_slip)
      if (.not. allocated(error)) call side(.false., in%bodies(p%master), nmaster, master_facets, master_law, &
         & master_slip, p%master_facets, p%master_law, p%master_slip)
      if (.not. allocated(error) .and. c_associated(pressure)) call c_f_pointer(pressure, p%pressure, &
         & [nslave*facet_npoints(element_facet_nodes(in%bodies(p%slave)%element_type))])
      if (allocated(error)) then
         call free_pair(p)
         call set_capi_error(err, error)
         return
      end if
      if (in%npair == size(in%pairs)) call grow_pairs(in)
      in%npair = in%npair + 1
      in%pairs(in%npair) = p
      index = in%npair - 1
   contains
      subroutine side(is_slave, b, n, facets, law, slip, f_out, law_out, slip_out)
         logical, intent(in) :: is_slave
         type(contact_body_type), intent(in) :: b
         integer(c_int), intent(in) :: n
         type(c_ptr), intent(in) :: facets, law, slip
         integer, pointer, contiguous, intent(inout) :: f_out(:, :), law_out(:)
         real(wp), pointer, contiguous, intent(inout) :: slip_out(:, :)
         integer(c_int), pointer :: ip(:, :), lp(:)
         integer, allocatable :: tmp(:, :)
         character(len=:), allocatable :: sname
         integer :: nfn

         sname = trim(merge('slave ', 'master', is_slave))
         nfn = element_facet_nodes(b%element_type)
         if (n < 1) then
            call fail('.n'//sname//' = '//itoa(n)//': a pair needs contact facets on both sides')
         else if (.not. (c_associated(facets) .and. c_associated(law))) then
            call fail('.'//sname//'_facets or '//sname//'_law is NULL')
         end if
         if (allocated(error)) return
         call c_f_pointer(facets, ip, [nfn, n])
         call one_based(ip, size(b%nodes, 2), sname//'_facets', tmp, error)
         if (allocated(error)) then
            error%message = pname//'.'//error%message(len('sprc_recover: ') + 1:)//' of bodies['// &
               & itoa(merge(slave, master, is_slave))//']'
            return
         end if
         allocate (f_out(nfn, n), law_out(n))
         f_out = tmp
         call c_f_pointer(law, lp, [n])
         law_out = int(lp)
         if (c_associated(slip)) call c_f_pointer(slip, slip_out, [b%dim, n])
      end subroutine side
      subroutine fail(message)
         character(len=*), intent(in) :: message
         call fatal_error(error, pname//message, stat_invalid_input)
      end subroutine fail
   end function sprc_contact_add_pair

   !> Recover the bodies in contact (SPRC_METHOD_SPRC or SPRC_METHOD_SPR); a new contact
   !> recovery or NULL with the error set.
   function sprc_recover_contact(errh, inh, method) result(rech) bind(C, name='sprc_recover_contact')
      type(c_ptr), value :: errh, inh
      integer(c_int), value :: method
      type(c_ptr) :: rech
      type(capi_error_type), pointer :: err
      type(capi_contact_input_type), pointer :: in
      type(capi_contact_recovery_type), pointer :: rec
      type(error_type), allocatable :: error
      type(method_code_type) :: code
      integer :: stat

      rech = c_null_ptr
      if (.not. get_input(errh, inh, 'sprc_recover_contact', err, in)) return
      call decode_method('sprc_recover_contact', int(method), .true., code, error)
      if (allocated(error)) then
         call set_capi_error(err, error)
         return
      end if
      allocate (rec, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_recover_contact: out of memory', stat=stat_out_of_memory)
         return
      end if
      call recover_contact_on_mesh(in%bodies(1:in%nbody), in%pairs(1:in%npair), code%method, rec%result, error, &
         & c_indices=.true., degree_above=code%degree_above, edges=code%edges)
      if (allocated(error)) then
         deallocate (rec)
         error%message = 'sprc_recover_contact: '//error%message
         call set_capi_error(err, error)
         return
      end if
      rech = c_loc(rec)
   end function sprc_recover_contact

   !> Body `body` (0-based) of a contact recovery as a new sprc_recovery (a copy: free it
   !> with sprc_delete_recovery); NULL with the error set.
   function sprc_get_contact_body(errh, rech, body) result(out) bind(C, name='sprc_get_contact_body')
      type(c_ptr), value :: errh, rech
      integer(c_int), value :: body
      type(c_ptr) :: out
      type(capi_error_type), pointer :: err
      type(capi_contact_recovery_type), pointer :: rec
      type(capi_recovery_type), pointer :: r
      integer :: stat

      out = c_null_ptr
      if (.not. get_result(errh, rech, 'sprc_get_contact_body', err, rec)) return
      if (body < 0 .or. body >= size(rec%result%bodies)) then
         call set_capi_error(err, message='sprc_get_contact_body: body = '//itoa(body)//' is not in 0..'// &
            & itoa(size(rec%result%bodies) - 1), stat=stat_invalid_input)
         return
      end if
      allocate (r, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_get_contact_body: out of memory', stat=stat_out_of_memory)
         return
      end if
      r%result = rec%result%bodies(body + 1)
      out = c_loc(r)
   end function sprc_get_contact_body

   !> The number of contact points of pair `pair` (0-based); -1 on error.
   function sprc_get_contact_points(errh, rech, pair) result(n) bind(C, name='sprc_get_contact_points')
      type(c_ptr), value :: errh, rech
      integer(c_int), value :: pair
      integer(c_int) :: n
      type(capi_error_type), pointer :: err
      type(capi_contact_recovery_type), pointer :: rec

      n = -1
      if (.not. get_result(errh, rech, 'sprc_get_contact_points', err, rec)) return
      if (.not. pair_ok(err, rec, pair, 'sprc_get_contact_points')) return
      n = rec%result%pairs(pair + 1)%npoints
   end function sprc_get_contact_points

   !> Pair `pair`'s values at its npoints points into the arrays given (any may be NULL):
   !> points, normals (slave, outward), tangential tractions of slave and master and the
   !> jump [npoints][dim]; weights, pressure (slave), pressure_master [npoints].
   subroutine sprc_get_contact_pair(errh, rech, pair, npoints, points, weights, normals, pressure, pressure_master, &
         & traction_tangential, traction_tangential_master, jump) bind(C, name='sprc_get_contact_pair')
      type(c_ptr), value :: errh, rech
      integer(c_int), value :: pair, npoints
      type(c_ptr), value :: points, weights, normals, pressure, pressure_master, traction_tangential, &
         & traction_tangential_master, jump
      character(len=*), parameter :: entry = 'sprc_get_contact_pair'
      type(capi_error_type), pointer :: err
      type(capi_contact_recovery_type), pointer :: rec

      if (.not. get_result(errh, rech, entry, err, rec)) return
      if (.not. pair_ok(err, rec, pair, entry)) return
      associate (p => rec%result%pairs(pair + 1))
         if (npoints /= p%npoints) then
            call set_capi_error(err, message=entry//': npoints = '//itoa(npoints)//' but pair '//itoa(pair)// &
               & ' has '//itoa(p%npoints)//' points', stat=stat_invalid_input)
            return
         end if
         call put2(points, p%x)
         call put1(weights, p%w)
         call put2(normals, p%normal)
         call put1(pressure, p%pressure)
         call put1(pressure_master, p%pressure_master)
         call put2(traction_tangential, p%traction_tangential)
         call put2(traction_tangential_master, p%traction_tangential_master)
         call put2(jump, p%jump)
      end associate
   contains
      subroutine put1(ptr, v)
         type(c_ptr), intent(in) :: ptr
         real(wp), intent(in) :: v(:)
         real(c_double), pointer :: o(:)
         if (.not. c_associated(ptr)) return
         call c_f_pointer(ptr, o, [size(v)])
         o = v
      end subroutine put1
      subroutine put2(ptr, v)
         type(c_ptr), intent(in) :: ptr
         real(wp), intent(in) :: v(:, :)
         real(c_double), pointer :: o(:, :)
         if (.not. c_associated(ptr)) return
         call c_f_pointer(ptr, o, shape(v))
         o = v
      end subroutine put2
   end subroutine sprc_get_contact_pair

   logical function pair_ok(err, rec, pair, entry)
      type(capi_error_type), intent(inout) :: err
      type(capi_contact_recovery_type), intent(in) :: rec
      integer(c_int), intent(in) :: pair
      character(len=*), intent(in) :: entry
      pair_ok = pair >= 0 .and. pair < size(rec%result%pairs)
      if (.not. pair_ok) call set_capi_error(err, message=entry//': pair = '//itoa(pair)//' is not in 0..'// &
         & itoa(size(rec%result%pairs) - 1), stat=stat_invalid_input)
   end function pair_ok

   !> Free the input `*ptr` (not the caller's arrays) and set it to NULL; NULL is a no-op.
   subroutine sprc_delete_contact_input(ptr) bind(C, name='sprc_delete_contact_input')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_contact_input_type), pointer :: in
      integer :: k

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, in)
      do k = 1, in%nbody
         call free_body(in%bodies(k))
      end do
      do k = 1, in%npair
         call free_pair(in%pairs(k))
      end do
      deallocate (in)
      handle = c_null_ptr
   end subroutine sprc_delete_contact_input

   !> Free the contact recovery `*ptr` and set it to NULL; NULL is a no-op.
   subroutine sprc_delete_contact_recovery(ptr) bind(C, name='sprc_delete_contact_recovery')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_contact_recovery_type), pointer :: rec

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, rec)
      deallocate (rec)
      handle = c_null_ptr
   end subroutine sprc_delete_contact_recovery

   !> The copies the input owns (index arrays); the caller's arrays are left alone.
   subroutine free_body(b)
      type(contact_body_type), intent(inout) :: b
      if (associated(b%connectivity)) deallocate (b%connectivity)
      if (associated(b%facet_nodes)) deallocate (b%facet_nodes)
      if (associated(b%facet_kind)) deallocate (b%facet_kind)
   end subroutine free_body

   subroutine free_pair(p)
      type(contact_pair_type), intent(inout) :: p
      if (associated(p%slave_facets)) deallocate (p%slave_facets)
      if (associated(p%master_facets)) deallocate (p%master_facets)
      if (associated(p%slave_law)) deallocate (p%slave_law)
      if (associated(p%master_law)) deallocate (p%master_law)
   end subroutine free_pair

   subroutine grow_bodies(in)
      type(capi_contact_input_type), intent(inout) :: in
      type(contact_body_type), allocatable :: tmp(:)
      allocate (tmp(2*size(in%bodies)))
      tmp(1:in%nbody) = in%bodies(1:in%nbody)
      call move_alloc(tmp, in%bodies)
   end subroutine grow_bodies

   subroutine grow_pairs(in)
      type(capi_contact_input_type), intent(inout) :: in
      type(contact_pair_type), allocatable :: tmp(:)
      allocate (tmp(2*size(in%pairs)))
      tmp(1:in%npair) = in%pairs(1:in%npair)
      call move_alloc(tmp, in%pairs)
   end subroutine grow_pairs

   logical function get_input(errh, inh, entry, err, in) result(ok)
      type(c_ptr), intent(in) :: errh, inh
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(capi_contact_input_type), pointer, intent(out) :: in

      in => null()
      ok = get_capi_error(errh, err)
      if (.not. ok) return
      ok = c_associated(inh)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the contact input handle is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(inh, in)
   end function get_input

   logical function get_result(errh, rech, entry, err, rec) result(ok)
      type(c_ptr), intent(in) :: errh, rech
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(capi_contact_recovery_type), pointer, intent(out) :: rec

      rec => null()
      ok = get_capi_error(errh, err)
      if (.not. ok) return
      ok = c_associated(rech)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the contact recovery handle is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(rech, rec)
   end function get_result

end module sprc_capi_contact_recovery
