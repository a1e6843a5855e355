# Helpers shared by every component's CMakeLists.txt.

# studio_test(NAME name SOURCES a.cc b.cc LIBS lib... [LABELS unit|integration|gl|dataset] [TIMEOUT s] [SERIAL])
# One gtest binary per call; tests are discovered individually so ctest reports each case.
function(studio_test)
  # SERIAL: ctest runs the binary's tests alone (RUN_SERIAL), for tests whose bounds need the
  # machine's whole share (a running studio that must keep up with its capture rings).
  cmake_parse_arguments(T "SERIAL" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 120)
  endif()
  if(STUDIO_SANITIZE)
    math(EXPR T_TIMEOUT "${T_TIMEOUT} * 3")  # ASan + UBSan at -O1 run the same work 2-4x slower
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${T_NAME} PRIVATE
    STUDIO_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    STUDIO_SHARED_DATA="${STUDIO_SHARED_DATA}"
    STUDIO_BINARY_DIR="${PROJECT_BINARY_DIR}")
  set(serial "")
  if(T_SERIAL)
    set(serial RUN_SERIAL TRUE)
  endif()
  # LABELS are not passed in PROPERTIES: gtest_discover_tests flattens every property value into
  # one argument list (set_tests_properties(... LABELS integration gl TIMEOUT 300)), so a second
  # label would be read as a property name and the pairs after it (TIMEOUT) lost. They are set
  # after discovery instead, by an include file ctest reads after the one that adds the tests
  # (${T_NAME}_TESTS is the list gtest_discover_tests defines). tests/ctest_properties_check.py
  # checks that every test ends up with a TIMEOUT and its labels.
  gtest_discover_tests(${T_NAME}
    PROPERTIES ${serial} TIMEOUT ${T_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
  set(labels_file "${CMAKE_CURRENT_BINARY_DIR}/${T_NAME}_labels.cmake")
  file(WRITE "${labels_file}"
    "if(DEFINED ${T_NAME}_TESTS)\n"
    "  set_tests_properties(\${${T_NAME}_TESTS} PROPERTIES LABELS [==[${T_LABELS}]==])\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${labels_file}")
  foreach(label ${T_LABELS})
    set_property(GLOBAL APPEND PROPERTY STUDIO_TESTS_${label} ${T_NAME})
  endforeach()
endfunction()

# studio_tests_<label> (unit, integration, gl, dataset): builds every gtest binary of that label,
# so `./studio test --asan -L unit` (CI's sanitizer run) builds only what it runs. Created once,
# at the end of the top-level CMakeLists.txt, when every studio_test() is known.
function(studio_label_targets)
  foreach(label unit integration gl dataset)
    get_property(targets GLOBAL PROPERTY STUDIO_TESTS_${label})
    if(targets)
      add_custom_target(studio_tests_${label} DEPENDS ${targets})
    endif()
  endforeach()
endfunction()
get_property(studio_label_targets_deferred GLOBAL PROPERTY STUDIO_LABEL_TARGETS_DEFERRED)
if(NOT studio_label_targets_deferred)
  set_property(GLOBAL PROPERTY STUDIO_LABEL_TARGETS_DEFERRED ON)
  cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL studio_label_targets)
endif()

# studio_bench(NAME name SOURCES a.cc LIBS lib...): a Google Benchmark binary, run by ./studio bench.
function(studio_bench)
  if(NOT STUDIO_BENCH)
    return()
  endif()
  cmake_parse_arguments(B "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${B_NAME} ${B_SOURCES})
  target_link_libraries(${B_NAME} PRIVATE ${B_LIBS} benchmark::benchmark)
  target_compile_definitions(${B_NAME} PRIVATE
    STUDIO_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    STUDIO_SHARED_DATA="${STUDIO_SHARED_DATA}"
    STUDIO_BINARY_DIR="${PROJECT_BINARY_DIR}")
  set_property(GLOBAL APPEND PROPERTY STUDIO_BENCHMARKS ${B_NAME})
endfunction()

# studio_fuzz(NAME name SOURCES a.cc LIBS lib...): a libFuzzer target, built only with STUDIO_FUZZ (clang).
function(studio_fuzz)
  if(NOT STUDIO_FUZZ)
    return()
  endif()
  cmake_parse_arguments(F "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${F_NAME} ${F_SOURCES})
  target_compile_options(${F_NAME} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_options(${F_NAME} PRIVATE -fsanitize=fuzzer,address,undefined)
  target_link_libraries(${F_NAME} PRIVATE ${F_LIBS})
endfunction()

include(GoogleTest)
