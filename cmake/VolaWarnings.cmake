# Warnings and the instruction-set baseline for the project's own targets.
function(vola_target_defaults target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>)
  if(VOLA_X86_64_V2)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-mpopcnt -msse4.2>)
  endif()
endfunction()
