# Runs every example scene in scenes/ (the 2013 paper's figures) to its end and checks, from the
# last row of its frames.csv, that every scheduled cut was applied and that the model ended with
# the particle and element counts the figure's cut implies (a cut that silently selected other
# faces would change them). Output frames are cut to 2, so the run costs the stepping only.
#
#   cmake -DSEWN=<sewn executable> -DSCENES=<scenes dir> -DWORK=<scratch dir> [-DSANITIZED=ON] -P example_scenes.cmake
#
# Expected counts per scene: particles after the cuts (3-unsew duplicates the particles that
# stop being joined through other volumes) and live elements (piercing removes some), and
# optionally a time to stop at (sewn run --until) for a scene whose stepping after its last cut
# would cost minutes under the sanitizers. Every scene must be listed, so a new scene cannot go
# unchecked.
set(expect_fig05_unsew           "20;4")    # 18 points, v1 and v2 duplicated (paper's Fig. 5)
set(expect_fig08_ten_faces       "110;45")  # 12 section points + 2 beside the neck duplicated
set(expect_fig09_frog            "32959;26125;0.024")  # the 5x5 points of the thigh section duplicated
set(expect_fig10_knife           "104;45")  # the 8 points above the hinge row duplicated
set(expect_fig11_three_then_nine "112;45")  # all 16 points of the section duplicated
set(expect_fig12_pierce          "96;42")   # enclosed cavity: no point freed, 3 cubes removed
set(expect_table1_hex            "8;1")     # the paper's timing set-ups: no cut
set(expect_table1_tets           "8;5")
set(expect_sofa_8x8x10           "891;640")
set(expect_tet_beam_5x7x9        "480;1890")
set(expect_newton_cantilever     "189;80")   # backward Euler by Newton on the mass-spring beam
set(expect_solid_cantilever      "189;480")  # the same beam as finite-element tetrahedra
set(expect_shell_plate           "85;128")   # membranes and Morley bending on 16x4x2 triangles
set(expect_obstacles_spike       "81;32")    # rigid obstacles: no cut
set(expect_mixed_fin             "177;449")  # 411 tetrahedra, 34 shell triangles, 4 rod segments; the top face a label
set(expect_rod_spring            "101;100")  # a rod alone: 100 segments, the first edge clamped
# The 2019 paper's Table 1 scenes (meshes from `sewn make-mesh`), two steps each (the umbrella
# one: a step of its 3168 nodes costs about a second): every node simulated, every cell an element.
set(expect_s04_frisbee           "289;576;0.07")
set(expect_s04_umbrella          "3168;6342;0.034")
set(expect_s04_sticky_hands      "200;311;0.07")
set(expect_s04_jellyfish         "1465;1727;0.07")
set(expect_s04_toy_ball          "349;525;0.07")
set(expect_s04_sandwich          "198;760;0.07")
set(expect_s04_toy_tunnel        "620;1260;0.07")  # the figures' scenes: 1200 triangles + 60 rod edges
set(expect_s04_anglerfish        "231;653;0.07")   # 592 tetrahedra, 41 fin triangles, 20 antenna edges
# The 2014 paper's adaptive refinement, stopped once refinement has run (their ends cost minutes
# under the sanitizers): counts = particles and live hexahedra the criterion has made by then.
set(expect_refine_fig09_spike    "1421;884;0.25")  # 100 hexahedra, 112 of them refined by t = 0.25 s
set(expect_refine_fig11_beam     "1045;744;0.5")   # 2 roots pre-refined to 16, then 104 of those and their children
set(expect_refine_fig08_cut_path "540;463")        # 441 points + the path's 14 inner points duplicated + 85 from 21 quads refined 1:4 (400 - 21 + 84 quads)
set(expect_refine_fig10_rabbit   "3460;2480")       # bunny00.off voxelized, 324 hexahedra refined; skipped without the file

# Under the sanitizers (-DSANITIZED=ON) these scenes are left to the release run of this test: a
# step of the umbrella's 3168 nodes costs about a second in release and tens under ASan, and
# every code path it takes (shells, rods, connections, Newton) runs in the smaller s04 scenes.
set(release_only s04_umbrella)

foreach(v SEWN SCENES WORK)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "example_scenes.cmake: -D${v}=... is required")
  endif()
endforeach()

file(GLOB scene_files "${SCENES}/*.json")
list(LENGTH scene_files n)
if(n EQUAL 0)
  message(FATAL_ERROR "no scene in ${SCENES}")
endif()
file(REMOVE_RECURSE "${WORK}")
set(failures "")
foreach(scene IN LISTS scene_files)
  get_filename_component(name "${scene}" NAME_WE)
  if(NOT DEFINED expect_${name})
    list(APPEND failures "${name}: no expected counts in example_scenes.cmake")
    continue()
  endif()
  list(FIND release_only "${name}" release_only_index)
  if(SANITIZED AND release_only_index GREATER -1)
    message(STATUS "${name}: left to the release run (sanitized build)")
    continue()
  endif()
  list(GET expect_${name} 0 want_particles)
  list(GET expect_${name} 1 want_elements)
  file(READ "${scene}" json)
  string(JSON want_cuts ERROR_VARIABLE no_cuts LENGTH "${json}" cuts)
  if(no_cuts)
    set(want_cuts 0)
  endif()
  set(until "")
  list(LENGTH expect_${name} n_expect)
  if(n_expect GREATER 2)
    list(GET expect_${name} 2 t)
    set(until --until ${t})
  endif()
  set(out "${WORK}/${name}")
  execute_process(COMMAND "${SEWN}" run "${scene}" --out "${out}" --frames 2 ${until} --quiet
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    list(APPEND failures "${name}: sewn run exited with ${rc}: ${err}")
    continue()
  endif()
  if(err MATCHES "skipped: ")  # optional data absent (scenes/fetch_data.sh)
    message(STATUS "${name}: ${err}")
    continue()
  endif()
  file(STRINGS "${out}/frames.csv" rows)
  list(GET rows 0 header)
  list(GET rows -1 last)
  string(REPLACE "," ";" header "${header}")
  string(REPLACE "," ";" last "${last}")
  foreach(col cuts particles elements)
    list(FIND header ${col} i)
    if(i LESS 0)
      message(FATAL_ERROR "frames.csv has no column '${col}'")
    endif()
    list(GET last ${i} got_${col})
  endforeach()
  foreach(col cuts particles elements)
    if(NOT got_${col} EQUAL want_${col})
      list(APPEND failures "${name}: ${col} at the end = ${got_${col}}, expected ${want_${col}}")
    endif()
  endforeach()
  message(STATUS "${name}: ${got_cuts} cuts, ${got_particles} particles, ${got_elements} elements")
endforeach()
if(failures)
  string(REPLACE ";" "\n  " failures "${failures}")
  message(FATAL_ERROR "example scenes:\n  ${failures}")
endif()
