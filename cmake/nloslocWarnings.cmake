# nlosloc_target_warnings(<target>): warnings for nlosloc's own compiled targets (tests, bench, bindings).
# -Werror only with NLOSLOC_WERROR=ON; nothing here reaches consumers (the INTERFACE target stays clean).
function(nlosloc_target_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic $<$<BOOL:${NLOSLOC_WERROR}>:-Werror>)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12)
      # GCC >= 12 reports -Warray-bounds inside Eigen's vectorised kernels for Dynamic vectors with a fixed
      # maximum size (Matrix<double, Dynamic, 1, 0, 3, 1>) on code paths that never run (a known GCC 12
      # false positive). Real out-of-bounds accesses are the asan preset's job.
      target_compile_options(${target} PRIVATE -Wno-array-bounds)
    endif()
  elseif(MSVC)
    target_compile_options(${target} PRIVATE /W4 $<$<BOOL:${NLOSLOC_WERROR}>:/WX>)
  endif()
endfunction()
