program sprc_main
   implicit none
   print '(a)', 'sprc'
end program sprc_main
