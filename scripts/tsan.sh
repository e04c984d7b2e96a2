#!/usr/bin/env bash
# ThreadSanitizer over the multi-threaded parts (scripts/test.sh runs it; CI too): the solver
# threads (any thread count, the same hash), the camera system's render and conversion
# threads, the real-time run loop, and lockstep over DDS with agent processes (the server's
# command listener runs in Cyclone's receive thread; pipelined, its frame sender thread). Builds build-tsan/ (gcc,
# -fsanitize=thread): the libraries, the agent program and one test program of those tests
# (tests/CMakeLists.txt); any data race fails the test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSIMSOCCER_TSAN=ON > /dev/null
cmake --build build-tsan --target simsoccer_thread_tests
# Third-party libraries are not instrumented: TSan cannot see their own synchronisation,
# so reports inside them (Cyclone DDS, OpenCV's parallel_for_ workers, GDAL) are
# suppressed by library in scripts/tsan.supp; our own threads' hand-offs are checked.
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/scripts/tsan.supp"
ctest --test-dir build-tsan --output-on-failure -j "$(nproc)" \
  -R '^(Determinism\.AnyNumberOfSolverThreads|CameraSystem\.|RunLoop\.|Net\.LockstepIsDeterministic|NetPipelined\.)'
