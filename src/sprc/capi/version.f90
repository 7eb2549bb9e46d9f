!> C API, version: the library's version as one integer, to check at run
!> time against the header's SPRC_VERSION.
module sprc_capi_version
   use, intrinsic :: iso_c_binding, only: c_int
   use sprc_version, only: sprc_version_number
   implicit none
   private

   public :: sprc_get_version

contains

   !> 10000*major + 100*minor + patch.
   function sprc_get_version() result(version) bind(C, name='sprc_get_version')
      integer(c_int) :: version
      version = sprc_version_number
   end function sprc_get_version

end module sprc_capi_version
