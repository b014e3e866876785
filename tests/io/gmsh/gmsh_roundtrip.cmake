# CTest driver: meshes each .geo with the real gmsh CLI into MSH 2.2, MSH 4.1, MEDIT and legacy
# VTK, keeps gmsh's log, then runs the checker on the results.
#   cmake -DGMSH=... -DGEO_DIR=... -DOUT=... -DCHECKER=... -P gmsh_roundtrip.cmake
# Without gmsh it prints SEWN-SKIP (CTest marks the test skipped), unless SEWN_CI is set: CI
# installs gmsh, so there its absence is a failure.
if(NOT GMSH OR NOT EXISTS "${GMSH}")
  if(DEFINED ENV{SEWN_CI})
    message(FATAL_ERROR "gmsh is not installed but SEWN_CI is set: the Gmsh round-trip test must run in CI")
  endif()
  message("SEWN-SKIP: gmsh not found; install it (tools/bootstrap) to run the Gmsh round trip")
  return()
endif()
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
file(GLOB geos "${GEO_DIR}/*.geo")
foreach(geo IN LISTS geos)
  get_filename_component(name "${geo}" NAME_WE)
  foreach(fmt msh22 msh41 mesh vtk)
    set(ext msh)
    if(fmt STREQUAL "mesh" OR fmt STREQUAL "vtk")
      set(ext ${fmt})
    endif()
    execute_process(COMMAND "${GMSH}" "${geo}" -3 -format ${fmt} -o "${OUT}/${name}.${fmt}.${ext}"
                    RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
    file(WRITE "${OUT}/${name}.${fmt}.log" "${log}")
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gmsh failed on ${geo} (-format ${fmt}):\n${log}")
    endif()
  endforeach()
endforeach()
execute_process(COMMAND "${CMAKE_COMMAND}" -E env "SEWN_GMSH_OUT=${OUT}" "${CHECKER}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the Gmsh round-trip checks failed")
endif()
