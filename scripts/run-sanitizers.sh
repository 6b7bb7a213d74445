#!/usr/bin/env bash
# The sanitizer and fuzzing job of CI (scripts/run-tests.sh runs it after the test suite; it may be
# run alone). Bounded to a few minutes on 2 cores:
#  1. configures ./build-sanitize with clang, -DPNEUFEM_FUZZ=ON (AddressSanitizer + UBSan, undefined
#     behaviour aborts; the libraries instrumented for libFuzzer too, so one build serves both) and
#     asserts on (-O1, no NDEBUG); builds only the readers' libraries, their tests and the fuzzers
#     (no VTK, no app);
#  2. runs the readers' tests under the sanitizers: the deck reader and writer (test_inp_reader,
#     test_inp_read_sets, test_inp_read_loads, test_inp_surface_elements, test_inp_writer,
#     test_inp_assembly, test_inp_text) and a deck through the scene (test_angle_frame,
#     test_build_model), the scene reader and its typed settings (test_scene, test_scene_settings,
#     test_key_limits) and the measurement and DeepLabCut readers (test_measurements) — the code that meets users' files,
#     in suites of seconds (but the three tests that bend an actuator); the solver suites run for
#     minutes and read no user input;
#  3. runs each fuzzer over its seed corpus (fuzz/corpus/) and on new inputs for
#     PNEUFEM_FUZZ_SECONDS (default 20) each (scripts/fuzz.sh).
# Any sanitizer report, failed test or fuzzer finding fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${PNEUFEM_SANITIZE_BUILD:-build-sanitize}
seconds=${PNEUFEM_FUZZ_SECONDS:-20}
tests=(test_inp_reader test_inp_read_sets test_inp_read_loads test_inp_surface_elements test_inp_writer test_inp_assembly
       test_inp_text test_angle_frame test_build_model test_scene test_scene_settings test_key_limits test_measurements)
# The three tests that bend an actuator (a solver run, minutes under ASan) read no input their
# siblings do not: left to the normal suite.
cxx=$(command -v clang++-14 || command -v clang++ || true)
if [ -z "$cxx" ]; then
  echo "run-sanitizers: clang++ not found; scripts/install-deps.sh installs clang-14 and libclang-rt-14-dev" >&2
  exit 1
fi
start=$(date +%s)
cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DPNEUFEM_FUZZ=ON -DPNEUFEM_BUILD_BENCH=OFF \
  -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target "${tests[@]}" pneufem_fuzzers
built=$(date +%s)
labels=$(IFS='|'; echo "${tests[*]}")
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$build" -L "^($labels)\$" -E "Bends" -j "$(nproc)" --output-on-failure --timeout 600
tested=$(date +%s)
./scripts/fuzz.sh "$build" "$seconds"
echo "run-sanitizers: build $((built - start)) s, sanitized tests $((tested - built)) s, fuzzing $(($(date +%s) - tested)) s"
