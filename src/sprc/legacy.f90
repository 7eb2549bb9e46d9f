!> F77-friendly entry points for legacy Fortran FE codes: explicit-shape `double precision`
!> and `integer` arrays, integer codes, `stat` / `errmsg`. Never stops, never prints.
!>
!> Integer codes (part of the C API; never renumber):
!> - element type (VTK cell type ids): tri3 = 5, quad4 = 9, tet4 = 10, hex8 = 12,
!>   quad9 = 28, hex27 = 29 (VTK node order, sprc_recovery_caller_mesh_element);
!> - analysis: plane stress = 1, plane strain = 2, solid (3D) = 3;
!> - method: SPR = 1, SPR-C = 2 (patch degree 'auto': SPR at the element degree p, SPR-C at
!>   p + 1 for quad9 and hex27), plus optionally the flags of the C API: 256 the patch degree
!>   p + 1, 512 the degree p (SPRC_RECOVERY_P_PLUS_1, SPRC_RECOVERY_P; not both), and for
!>   sprc_recover_contact_mesh 1024 no edge field at the edges of frictionless contact zones
!>   (SPRC_CONTACT_NO_EDGES);
!> - facet kind: traction = 1 (value in ftrac), symmetry = 2, free = 3 (zero traction),
!>   pressure = 4 (p = ftrac(1, f), t = -p n with the facet's own normal at each point);
!> - stat: 0 success, 1 invalid input, 2 singular (a patch stayed rank deficient),
!>   4 not converged (an inverse map), 8 internal (sprc_core_error).
!> On failure every output array is zero and errmsg holds the message (truncated to its
!> length; blank on success).
module sprc_legacy
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, stat_success, fatal_error
   use sprc_core_error, only: stat_invalid_input
   use sprc_core_text, only: itoa
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval, coded_degree
   use sprc_recovery_caller_mesh_check, only: method_code_type, decode_method
   use sprc_contact_caller_mesh_recovery, only: contact_body_type, contact_pair_type, mesh_contact_recovery_type, &
      & recover_contact_on_mesh
   implicit none
   private

   public :: sprc_recover_mesh, sprc_recover_contact_mesh

contains

   !> Recover the stresses of a caller's mesh, estimate the error and evaluate the recovered
   !> field at points (sprc_recovery_caller_mesh, recover_on_mesh and mesh_recovery_eval).
   !>
   !> Inputs: ndim (2 or 3); nnode, coords(ndim, nnode); etype; nen, nelem,
   !> conn(nen, nelem) (1-based); ngp, gp(ndim, ngp, nelem) physical integration points,
   !> gw(ngp, nelem) weight*|J|, nstr (3 in 2D, 6 in 3D), gs(nstr, ngp, nelem) FE stresses
   !> (Voigt xx, yy, xy / xx, yy, zz, xy, yz, xz); analysis, young, poisson, method;
   !> bforce(ndim) constant body force (zeros for none); nfacet (>= 0), nfn (nodes per facet:
   !> 2 tri3 / quad4, 3 quad9 / tet4, 4 hex8, 9 hex27), fnodes(nfn, nfacet), fkind(nfacet),
   !> ftrac(ndim, nfacet) (used for traction facets only); npts (>= 0), xpts(ndim, npts),
   !> epts(npts) the element of each point (0: search).
   !> Outputs: nodal(nstr, nnode) nodal stresses, elerr(nelem) element ZZ errors (energy
   !> norm), glerr the global estimate, eta the estimated relative error, spts(nstr, npts)
   !> the recovered field at the points, stat, errmsg.
   subroutine sprc_recover_mesh(ndim, nnode, coords, etype, nen, nelem, conn, ngp, gp, gw, nstr, gs, analysis, &
         & young, poisson, method, bforce, nfacet, nfn, fnodes, fkind, ftrac, npts, xpts, epts, nodal, elerr, &
         & glerr, eta, spts, stat, errmsg)
      integer, intent(in) :: ndim, nnode, etype, nen, nelem, ngp, nstr, analysis, method, nfacet, nfn, npts
      double precision, intent(in) :: coords(ndim, nnode)
      integer, intent(in) :: conn(nen, nelem)
      double precision, intent(in) :: gp(ndim, ngp, nelem), gw(ngp, nelem), gs(nstr, ngp, nelem)
      double precision, intent(in) :: young, poisson, bforce(ndim)
      integer, intent(in) :: fnodes(nfn, nfacet), fkind(nfacet)
      double precision, intent(in) :: ftrac(ndim, nfacet)
      double precision, intent(in) :: xpts(ndim, npts)
      integer, intent(in) :: epts(npts)
      double precision, intent(out) :: nodal(nstr, nnode), elerr(nelem), glerr, eta, spts(nstr, npts)
      integer, intent(out) :: stat
      character(len=*), intent(out) :: errmsg
      type(mesh_recovery_type) :: result
      type(method_code_type) :: code
      type(error_type), allocatable :: error

      nodal = 0.0d0
      elerr = 0.0d0
      glerr = 0.0d0
      eta = 0.0d0
      spts = 0.0d0
      stat = stat_success
      errmsg = ''
      call decode_method('sprc_recover_mesh', method, .false., code, error)
      if (.not. allocated(error)) call recover_on_mesh(ndim, analysis, real(coords, wp), etype, conn, real(gp, wp), &
         & real(gw, wp), real(gs, wp), real(young, wp), real(poisson, wp), code%method, result, error, &
         & body_force=real(bforce, wp), facet_nodes=fnodes, facet_kind=fkind, facet_traction=real(ftrac, wp), &
         & degree=coded_degree(code, etype))
      if (.not. allocated(error)) call mesh_recovery_eval(result, real(xpts, wp), spts, error, epts)
      if (allocated(error)) then
         stat = error%stat
         errmsg = error%message
         spts = 0.0d0
         return
      end if
      nodal = result%nodal
      elerr = result%elem_err
      glerr = result%err
      eta = result%eta
   end subroutine sprc_recover_mesh

   !> Recover two bodies in contact, each on its own mesh (sprc_contact_caller_mesh_recovery): body 1
   !> the slave, body 2 the master of one pair; no other boundary facets (the modern API,
   !> `recover_contact_on_mesh`, takes them, and several bodies and pairs).
   !>
   !> Inputs: ndim, nstr, analysis, method (as sprc_recover_mesh); per body b = 1, 2: nnodeb,
   !> coordsb(ndim, nnodeb), etypeb, nenb, nelemb, connb(nenb, nelemb) (1-based), ngpb,
   !> gpb(ndim, ngpb, nelemb), gwb(ngpb, nelemb), gsb(nstr, ngpb, nelemb), youngb, poissonb;
   !> its contact facets: nfnb nodes per facet, ncfb facets, cfacb(nfnb, ncfb) (1-based,
   !> element sides), claw b(ncfb) the law per facet (0 open, 1 frictionless, 2 slip, 3
   !> stick), cslipb(ndim, ncfb) its slip direction relative to the other body (read on slip
   !> facets); mu the friction coefficient; mpts the room for contact points.
   !> Outputs: nodalb(nstr, nnodeb), elerrb(nelemb), glerrb, etab per body; npts the contact
   !> points (the quadrature points of body 1's contact facets, facet by facet: nq ncf1, nq =
   !> 2 on lines, 3 on line3 / tri3 faces, 4 on quad4 faces, 9 on quad9 faces), xc(ndim, npts)
   !> their coordinates, pc(npts) and pcm(npts) the recovered pressure of body 1 and of body
   !> 2 (-n.sigma*.n, n body 1's outward normal), jc(ndim, npts) the traction jump
   !> (sigma*_1 - sigma*_2) n; stat, errmsg. mpts < npts is an error (stat 1) that names npts.
   subroutine sprc_recover_contact_mesh(ndim, nstr, analysis, method, &
         & nnode1, coords1, etype1, nen1, nelem1, conn1, ngp1, gp1, gw1, gs1, young1, poisson1, &
         & nnode2, coords2, etype2, nen2, nelem2, conn2, ngp2, gp2, gw2, gs2, young2, poisson2, &
         & nfn1, ncf1, cfac1, claw1, cslip1, nfn2, ncf2, cfac2, claw2, cslip2, mu, mpts, &
         & nodal1, elerr1, glerr1, eta1, nodal2, elerr2, glerr2, eta2, npts, xc, pc, pcm, jc, stat, errmsg)
      integer, intent(in) :: ndim, nstr, analysis, method, nnode1, etype1, nen1, nelem1, ngp1, nnode2, etype2, &
         & nen2, nelem2, ngp2, nfn1, ncf1, nfn2, ncf2, mpts
      double precision, intent(in), target :: coords1(ndim, nnode1), gp1(ndim, ngp1, nelem1), gw1(ngp1, nelem1), &
         & gs1(nstr, ngp1, nelem1), coords2(ndim, nnode2), gp2(ndim, ngp2, nelem2), gw2(ngp2, nelem2), &
         & gs2(nstr, ngp2, nelem2), cslip1(ndim, ncf1), cslip2(ndim, ncf2)
      integer, intent(in), target :: conn1(nen1, nelem1), conn2(nen2, nelem2), cfac1(nfn1, ncf1), claw1(ncf1), &
         & cfac2(nfn2, ncf2), claw2(ncf2)
      double precision, intent(in) :: young1, poisson1, young2, poisson2, mu
      double precision, intent(out) :: nodal1(nstr, nnode1), elerr1(nelem1), glerr1, eta1, nodal2(nstr, nnode2), &
         & elerr2(nelem2), glerr2, eta2, xc(ndim, mpts), pc(mpts), pcm(mpts), jc(ndim, mpts)
      integer, intent(out) :: npts, stat
      character(len=*), intent(out) :: errmsg
      type(contact_body_type) :: bodies(2)
      type(contact_pair_type) :: pairs(1)
      type(mesh_contact_recovery_type) :: res
      type(method_code_type) :: code
      type(error_type), allocatable :: error

      nodal1 = 0.0d0
      elerr1 = 0.0d0
      nodal2 = 0.0d0
      elerr2 = 0.0d0
      glerr1 = 0.0d0
      eta1 = 0.0d0
      glerr2 = 0.0d0
      eta2 = 0.0d0
      xc = 0.0d0
      pc = 0.0d0
      pcm = 0.0d0
      jc = 0.0d0
      npts = 0
      stat = stat_success
      errmsg = ''
      ! The arrays are double precision = real(wp) (sprc_core_kinds): used in place.
      bodies(1) = contact_body_type(dim=ndim, analysis=analysis, element_type=etype1, young=young1, &
         & poisson=poisson1, nodes=coords1, connectivity=conn1, gp=gp1, gw=gw1, gs=gs1)
      bodies(2) = contact_body_type(dim=ndim, analysis=analysis, element_type=etype2, young=young2, &
         & poisson=poisson2, nodes=coords2, connectivity=conn2, gp=gp2, gw=gw2, gs=gs2)
      pairs(1)%slave = 1
      pairs(1)%master = 2
      pairs(1)%slave_facets => cfac1
      pairs(1)%master_facets => cfac2
      pairs(1)%slave_law => claw1
      pairs(1)%master_law => claw2
      pairs(1)%slave_slip => cslip1
      pairs(1)%master_slip => cslip2
      pairs(1)%mu = mu
      call decode_method('sprc_recover_contact_mesh', method, .true., code, error)
      if (.not. allocated(error)) call recover_contact_on_mesh(bodies, pairs, code%method, res, error, &
         & degree_above=code%degree_above, edges=code%edges)
      if (.not. allocated(error)) then
         if (res%pairs(1)%npoints > mpts) call fatal_error(error, 'sprc_recover_contact_mesh: mpts = '//itoa(mpts)// &
            & ' but the contact facets have '//itoa(res%pairs(1)%npoints)//' points (npts)', stat_invalid_input)
      end if
      if (allocated(error)) then
         stat = error%stat
         errmsg = error%message
         if (allocated(res%pairs)) npts = res%pairs(1)%npoints
         return
      end if
      nodal1 = res%bodies(1)%nodal
      elerr1 = res%bodies(1)%elem_err
      glerr1 = res%bodies(1)%err
      eta1 = res%bodies(1)%eta
      nodal2 = res%bodies(2)%nodal
      elerr2 = res%bodies(2)%elem_err
      glerr2 = res%bodies(2)%err
      eta2 = res%bodies(2)%eta
      associate (p => res%pairs(1))
         npts = p%npoints
         xc(:, 1:npts) = p%x
         pc(1:npts) = p%pressure
         pcm(1:npts) = p%pressure_master
         jc(:, 1:npts) = p%jump
      end associate
   end subroutine sprc_recover_contact_mesh

end module sprc_legacy
