# Warnings and sanitizers live in INTERFACE targets; no global flags.
add_library(strata_warnings INTERFACE)
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  target_compile_options(strata_warnings INTERFACE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Wnon-virtual-dtor
    -Wold-style-cast -Woverloaded-virtual)
  if(STRATA_WERROR)
    target_compile_options(strata_warnings INTERFACE -Werror)
  endif()
endif()

add_library(strata_sanitize INTERFACE)
if(STRATA_FUZZ)
  # Coverage for libFuzzer in every module; the fuzz targets link -fsanitize=fuzzer.
  target_compile_options(strata_sanitize INTERFACE -fsanitize=fuzzer-no-link,address,undefined
    -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(strata_sanitize INTERFACE -fsanitize=address,undefined)
elseif(STRATA_SANITIZE)
  target_compile_options(strata_sanitize INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(strata_sanitize INTERFACE -fsanitize=address,undefined)
endif()
