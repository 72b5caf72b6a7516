# Project-wide compile options: warnings are errors; optional sanitizers.
# mocap_add_library(name SOURCES ... DEPS ...) and mocap_target_options(target)
# apply them uniformly, so every module builds the same way.

set(MOCAP_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion
    -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual
    -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough -Werror)

if(MOCAP_SANITIZE)
  string(REPLACE ";" "," _mocap_san "${MOCAP_SANITIZE}")
  add_compile_options(-fsanitize=${_mocap_san} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${_mocap_san})
  if("address" IN_LIST MOCAP_SANITIZE)
    # Eigen switches to its hand-made aligned malloc under ASan, while Debian's libceres
    # (built without ASan) frees Eigen storage with plain free(): the mix is a bad free.
    # glibc's and ASan's malloc both return 16-byte-aligned memory, which is all Eigen
    # needs here (no AVX flags), so keep Eigen on plain malloc everywhere.
    add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
  if("thread" IN_LIST MOCAP_SANITIZE AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # GCC 12 warns (-Wtsan) that TSan does not model std::atomic_thread_fence, which
    # Boost.Asio's std_fenced_block uses (the Foxglove server). Our own code uses no
    # standalone fence (grep atomic_thread_fence), so the warning is only Asio's.
    add_compile_options(-Wno-tsan)
  endif()
  message(STATUS "mocap: sanitizers ${_mocap_san}")
endif()

# UBSan's pointer-use checks (null, alignment: one type-mismatch check on every pointer
# access) make GCC spend ~40 % more time on Eigen/Ceres-heavy translation units (rigcal:
# 49 s -> 31 s without them at -O1). They are kept where bytes are reinterpreted as other
# types (image rows, PGM and datagram parsing, rings: core, rt, camera, formats, detect,
# client, hal, pipeline, publish, record, service, config, and the tests that write 16-bit
# images or raw buffers) and dropped in the numeric modules below, the `mocap` executable
# and the other tests, none of which casts pointers other than to bytes (grep
# reinterpret_cast); a null dereference there is still caught, by ASan's SEGV report.
# Every other UBSan check stays on everywhere.
set(MOCAP_UBSAN_NO_POINTER_CHECKS mocap_stereo mocap_identify mocap_kinematics mocap_rigcal
    mocap_track mocap_discover mocap_sim mocap_foxglove mocap)
set(MOCAP_UBSAN_POINTER_CHECKED_TESTS test_detect test_formats test_fuzz_corpus test_hal
    test_camera test_core test_client)

function(mocap_target_options target)
  target_compile_options(${target} PRIVATE ${MOCAP_WARNINGS})
  if("undefined" IN_LIST MOCAP_SANITIZE AND target IN_LIST MOCAP_UBSAN_NO_POINTER_CHECKS)
    target_compile_options(${target} PRIVATE -fno-sanitize=null,alignment)
  endif()
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR})
endfunction()

# mocap_add_library(<name> SOURCES <files...> DEPS <targets...>)
function(mocap_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  mocap_target_options(${name})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS})
endfunction()

# Aggregate targets: every test binary, and the ones labelled "concurrency" (the
# ThreadSanitizer job builds only those).
add_custom_target(mocap_all_tests)
add_custom_target(mocap_concurrency_tests)

# mocap_add_test(<name> SOURCES <files...> DEPS <targets...> [LABELS <labels...>]
#                [FIXTURES <ctest fixtures...>])
# Registers every TEST() of the executable with ctest. Label "concurrency" marks the
# tests that the ThreadSanitizer configuration runs. FIXTURES: ctest fixtures every test
# requires (set up once per ctest run, e.g. a recording several tests read).
function(mocap_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS;FIXTURES" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  # The allocation counter replaces global operator new/delete: it stays its own
  # translation unit in unity builds (deploy/test.sh), where GCC would otherwise see
  # the replacement and the callers together and flag free() of new'ed memory.
  foreach(src IN LISTS ARG_SOURCES)
    if(src MATCHES "tests/support/alloc_counter.cpp$")
      set_source_files_properties(${src} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
    endif()
  endforeach()
  mocap_target_options(${name})
  if(MOCAP_SANITIZE)
    # Sanitizer builds (deploy/test.sh) compile the tests' own code unoptimised: it is
    # mostly setup and assertions, while the code under test (the libraries) keeps the
    # build type's -O1. Saves a large share of the CI compile time.
    target_compile_options(${name} PRIVATE -O0)
    if("undefined" IN_LIST MOCAP_SANITIZE AND NOT name IN_LIST MOCAP_UBSAN_POINTER_CHECKED_TESTS)
      target_compile_options(${name} PRIVATE -fno-sanitize=null,alignment)  # see above
    endif()
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest_main GTest::gmock)
  # Where tests find the sources and the built `mocap` (environment variables override).
  target_compile_definitions(${name} PRIVATE MOCAP_TEST_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                             MOCAP_TEST_BINARY_DIR="${PROJECT_BINARY_DIR}")
  if("concurrency" IN_LIST ARG_LABELS)
    add_dependencies(mocap_concurrency_tests ${name})
  endif()
  add_dependencies(mocap_all_tests ${name})
  set(_props)
  if(ARG_LABELS)
    list(APPEND _props LABELS "${ARG_LABELS}")
  endif()
  if(ARG_FIXTURES)
    list(APPEND _props FIXTURES_REQUIRED "${ARG_FIXTURES}")
  endif()
  if(_props)
    list(PREPEND _props PROPERTIES)
  endif()
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR} ${_props} DISCOVERY_TIMEOUT 60)
endfunction()

# mocap_add_bench(<name> SOURCES <files...> DEPS <targets...>)
function(mocap_add_bench name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  mocap_target_options(${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} benchmark::benchmark)
endfunction()

# mocap_add_recording_fixture(<test> FIXTURE <fixture> OUT <dir> SIMULATE <args...>)
# A recording that several tests read, rendered once per ctest run: the test <test>
# sets up ctest fixture <fixture> (tests name it in mocap_add_test's FIXTURES) by running
# `mocap simulate <args> --threads 1` into <dir>.tmp and moving it to <dir> (a test never
# reads a half-written recording).
function(mocap_add_recording_fixture test_name)
  cmake_parse_arguments(ARG "" "FIXTURE;OUT" "SIMULATE" ${ARGN})
  list(JOIN ARG_SIMULATE " " _args)
  add_test(NAME ${test_name}
    COMMAND sh -c "rm -rf '${ARG_OUT}' '${ARG_OUT}.tmp' && $<TARGET_FILE:mocap> simulate ${_args} --threads 1 --out '${ARG_OUT}.tmp' >/dev/null && mv '${ARG_OUT}.tmp' '${ARG_OUT}'")
  set_tests_properties(${test_name} PROPERTIES FIXTURES_SETUP ${ARG_FIXTURE} TIMEOUT 300)
endfunction()
