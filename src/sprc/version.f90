!> Version of sprc. Keep in step with `version` in fpm.toml (a driver test checks).
module sprc_version
   implicit none
   private

   public :: sprc_version_string, sprc_version_number, get_sprc_version

   integer, parameter :: major = 0, minor = 1, patch = 0
   !> "major.minor.patch"
   character(len=*), parameter :: sprc_version_string = '0.1.0'
   !> 10000*major + 100*minor + patch, as `sprc_get_version` in the C API.
   integer, parameter :: sprc_version_number = 10000*major + 100*minor + patch

contains

   !> The three parts of the version.
   pure subroutine get_sprc_version(vmajor, vminor, vpatch)
      integer, intent(out), optional :: vmajor, vminor, vpatch
      if (present(vmajor)) vmajor = major
      if (present(vminor)) vminor = minor
      if (present(vpatch)) vpatch = patch
   end subroutine get_sprc_version

end module sprc_version
