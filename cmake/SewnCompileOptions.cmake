# Warning, optimisation and sanitizer flags shared by every Sewn target.
# sewn_module(<name>) turns a library into an exported, installable sewn::<name> module, a
# component of the installed package (cmake/SewnConfig.cmake.in lists what each one needs).

add_library(sewn_build_flags INTERFACE)
target_compile_options(sewn_build_flags INTERFACE -Wall -Wextra -Wpedantic)
if(SEWN_WERROR)
  target_compile_options(sewn_build_flags INTERFACE -Werror)
endif()
if(SEWN_NATIVE)
  target_compile_options(sewn_build_flags INTERFACE -march=native)
endif()
# GCC 12's basic-block (SLP) vectoriser miscompiles small aggregates when AVX-512 is enabled:
# an inlined call taking std::array<int64_t, 4>{1, 1, 0, 0} receives {1, 1, 1, 1} (at -O2 and
# -O3, -march=native on AVX-512 machines). Loop vectorisation and our explicit intrinsics are
# not affected; tests/cmap/test_toolchain.cpp fails where the flag is missing.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(sewn_build_flags INTERFACE -fno-tree-slp-vectorize)
endif()
if(SEWN_SANITIZE)
  target_compile_options(sewn_build_flags INTERFACE -fsanitize=${SEWN_SANITIZE} -fno-omit-frame-pointer
                         -fno-sanitize-recover=all)
  target_link_options(sewn_build_flags INTERFACE -fsanitize=${SEWN_SANITIZE})
endif()

# libFuzzer needs clang; with another compiler the fuzz targets are skipped, not an error, so
# one preset list works on every machine.
if(SEWN_FUZZ AND NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(STATUS "SEWN_FUZZ: libFuzzer needs clang (this is ${CMAKE_CXX_COMPILER_ID}): fuzz targets skipped")
  set(SEWN_FUZZ OFF)
endif()
if(SEWN_FUZZ AND SEWN_FUZZ_COVERAGE STREQUAL "all")
  # Every library the targets link gets coverage instrumentation; tests/fuzz adds the driver.
  target_compile_options(sewn_build_flags INTERFACE -fsanitize=fuzzer-no-link,address,undefined
                         -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(sewn_build_flags INTERFACE -fsanitize=address,undefined)
elseif(SEWN_FUZZ AND NOT SEWN_SANITIZE)
  # Only the listed modules are instrumented (the top-level CMakeLists adds that); the targets
  # still need the sanitizers everywhere.
  message(FATAL_ERROR "SEWN_FUZZ_COVERAGE='${SEWN_FUZZ_COVERAGE}' needs SEWN_SANITIZE (e.g. address,undefined)")
endif()

function(sewn_module name)
  add_library(sewn::${name} ALIAS sewn_${name})
  set_target_properties(sewn_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(sewn_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(sewn_${name} PUBLIC cxx_std_20)
  target_link_libraries(sewn_${name} PRIVATE $<BUILD_INTERFACE:sewn_build_flags>)
  # One export file per module, so that find_package(Sewn COMPONENTS <name>) loads only the
  # modules asked for (and those they need) and finds only their dependencies (SewnConfig.cmake.in).
  install(TARGETS sewn_${name} EXPORT Sewn_${name}Targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT Sewn_${name}Targets NAMESPACE sewn:: FILE Sewn-${name}-targets.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Sewn)
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
