!> F77-friendly entry points for legacy Fortran FE codes: explicit-shape `double precision`
!> and `integer` arrays, integer codes, `stat` / `errmsg`. Never stops, never prints.
!>
!> Integer codes (part of the C API; never renumber):
!> - element type (VTK cell type ids): tri3 = 5, quad4 = 9, tet4 = 10, hex8 = 12,
!>   quad9 = 28, hex27 = 29 (VTK node order, sprc_recovery_mesh_element);
!> - analysis: plane stress = 1, plane strain = 2, solid (3D) = 3;
!> - method: SPR = 1, SPR-C = 2 (patch degree 'auto': SPR at the element degree p, SPR-C at
!>   p + 1 for quad9 and hex27);
!> - facet kind: traction = 1 (value in ftrac), symmetry = 2, free = 3 (zero traction),
!>   pressure = 4 (p = ftrac(1, f), t = -p n with the facet's own normal at each point);
!> - stat: 0 success, 1 invalid input, 2 singular (a patch stayed rank deficient),
!>   4 not converged (an inverse map), 8 internal (sprc_core_error).
!> On failure every output array is zero and errmsg holds the message (truncated to its
!> length; blank on success).
module sprc_legacy
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, stat_success
   use sprc_recovery_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval
   implicit none
   private

   public :: sprc_recover_mesh

contains

   !> Recover the stresses of a caller's mesh, estimate the error and evaluate the recovered
   !> field at points (sprc_recovery_mesh, recover_on_mesh and mesh_recovery_eval).
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
      type(error_type), allocatable :: error

      nodal = 0.0d0
      elerr = 0.0d0
      glerr = 0.0d0
      eta = 0.0d0
      spts = 0.0d0
      stat = stat_success
      errmsg = ''
      call recover_on_mesh(ndim, analysis, real(coords, wp), etype, conn, real(gp, wp), real(gw, wp), real(gs, wp), &
         & real(young, wp), real(poisson, wp), method, result, error, body_force=real(bforce, wp), &
         & facet_nodes=fnodes, facet_kind=fkind, facet_traction=real(ftrac, wp))
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

end module sprc_legacy
