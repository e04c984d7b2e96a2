#!/usr/bin/env bash
# ThreadSanitizer over the multi-threaded parts (not in CI: a build of its own and slow
# tests): the solver threads (any thread count, the same hash), the camera system's render
# and conversion threads, the real-time run loop, and lockstep over DDS with agent
# processes (the server's command listener runs in Cyclone's receive thread). Builds
# build-tsan/ (gcc, -fsanitize=thread); any data race fails the test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSIMSOCCER_TSAN=ON > /dev/null
cmake --build build-tsan --target simsoccer_sim_tests simsoccer_unit_tests simsoccer_net_tests
# Third-party libraries are not instrumented: their internal races are suppressed by
# library (scripts/tsan.supp), and OpenCV's thread pool is turned off (its workers'
# hand-back is invisible to TSan), so our threads' hand-offs are what is checked.
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/scripts/tsan.supp"
export OPENCV_FOR_THREADS_NUM=1
ctest --test-dir build-tsan --output-on-failure -j 1 \
  -R '^(Determinism\.AnyNumberOfSolverThreads|CameraSystem\.|RunLoop\.|Net\.LockstepIsDeterministic)'
