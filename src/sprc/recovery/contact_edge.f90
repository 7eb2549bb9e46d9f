!> The stress field of the edge of a frictionless contact zone in 2D: the enrichment of the
!> SPR-C patches at the edge (sprc_recovery_contact_edge_fit), as the singular part is at re-entrant
!> corners (sprc_estimate_singular). Near the edge of a smooth frictionless contact the
!> pressure falls like the square root of the distance to the edge, p = K sqrt(-xi) on the
!> closed side, which no patch polynomial follows; the patches there recover sigma_h - S and
!> the field adds S back (eval_recovered_points).
!>
!> Frame: the edge point x_e, the unit tangent t of the surface pointing from the closed to
!> the open side, the body's unit outward normal n; xi = (x - x_e).t, eta = (x - x_e).n (eta <= 0
!> in the body; a point outside, in the gap of a curved contact, takes eta = 0). Westergaard's
!> field with Z(z) = -i K sqrt(z), z = xi + i eta, arg z in [-pi, 0]:
!>    s_xixi = Re Z - eta Im Z',  s_etaeta = Re Z + eta Im Z',  s_xieta = -eta Re Z',
!> in equilibrium without body force and compatible (Z analytic in the body), shear free on
!> eta = 0 (s_xieta = 0) with s_etaeta = Re Z: 0 on the open side xi > 0 (free) and -K sqrt(-xi)
!> on the closed side. The rotation to (x, y) holds for either orientation of (t, n): the two
!> bodies of a contact take the same t and opposite normals, and their tractions balance on the
!> surface. Stresses vanish like r^(1/2) at the edge.
module sprc_recovery_contact_edge
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: edge_stress

contains

   !> Voigt stresses s(1:3) = (xx, yy, xy) of the edge field of amplitude k (module notes) at x.
   pure subroutine edge_stress(point, tangent, normal, k, x, s)
      real(wp), intent(in) :: point(2), tangent(2), normal(2), k, x(2)
      real(wp), intent(out) :: s(3)
      complex(wp) :: sq, z, zp
      real(wp) :: xi, eta, sxx, syy, sxy

      xi = dot_product(x - point, tangent)
      eta = min(dot_product(x - point, normal), 0.0_wp)
      s = 0.0_wp
      if (xi == 0.0_wp .and. eta == 0.0_wp) return
      ! sqrt(z) on arg z in [-pi, 0]: the conjugate of the principal root of conj(z) (imaginary
      ! part |eta| >= +0, so the negative real axis maps to +i, never -i).
      sq = conjg(sqrt(cmplx(xi, abs(eta), kind=wp)))
      z = cmplx(0.0_wp, -k, kind=wp)*sq
      zp = cmplx(0.0_wp, -k, kind=wp)/(2.0_wp*sq)
      sxx = real(z, wp) - eta*aimag(zp)
      syy = real(z, wp) + eta*aimag(zp)
      sxy = -eta*real(zp, wp)
      s(1) = sxx*tangent(1)**2 + syy*normal(1)**2 + 2.0_wp*sxy*tangent(1)*normal(1)
      s(2) = sxx*tangent(2)**2 + syy*normal(2)**2 + 2.0_wp*sxy*tangent(2)*normal(2)
      s(3) = sxx*tangent(1)*tangent(2) + syy*normal(1)*normal(2) + sxy*(tangent(1)*normal(2) + tangent(2)*normal(1))
   end subroutine edge_stress

end module sprc_recovery_contact_edge
