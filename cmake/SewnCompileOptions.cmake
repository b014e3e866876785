# Warning, optimisation and sanitizer flags shared by every Sewn target.
# sewn_module(<name>) turns a library into an exported, installable sewn::<name> module.

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

function(sewn_module name)
  add_library(sewn::${name} ALIAS sewn_${name})
  set_target_properties(sewn_${name} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(sewn_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(sewn_${name} PUBLIC cxx_std_20)
  target_link_libraries(sewn_${name} PRIVATE $<BUILD_INTERFACE:sewn_build_flags>)
  install(TARGETS sewn_${name} EXPORT SewnTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
