# Warnings and the instruction-set baseline for the project's own targets.
function(vola_target_defaults target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>)
  # In a unity batch (CMAKE_UNITY_BUILD, as scripts/test builds) GCC treats every source
  # but the batch file as a header and warns when a class there holds a type from that
  # source's anonymous namespace; each such class is still defined in one batch only.
  if(CMAKE_UNITY_BUILD)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  endif()
  if(VOLA_X86_64_V2)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-mpopcnt -msse4.2>)
  endif()
endfunction()
