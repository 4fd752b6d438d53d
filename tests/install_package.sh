#!/bin/sh
# The installed package end to end (ctest -L install): installs this build into a staging prefix,
# builds a copy of examples/hello_pit against it in a clean folder, runs it, and checks that the
# example prints the state hash `ballpit run` prints for the same scene and steps; the installed
# Python module, where there is one, does too.
# Usage: install_package.sh BUILD_DIR SOURCE_DIR BALLPIT_EXECUTABLE WORK_DIR CXX_COMPILER
# (the build's compiler: the example must use the OpenMP runtime the libraries were built for)
set -eu
build=$1 source=$2 ballpit=$3 work=$4 cxx=$5
rm -rf "$work"
mkdir -p "$work"
fail() {
  echo "install_package: $1" >&2
  [ -f "$2" ] && cat "$2" >&2
  exit 1
}

cmake --install "$build" --prefix "$work/prefix" > "$work/install.log" 2>&1 || fail "cmake --install failed" "$work/install.log"
# The probe is installed and runs (with no arguments it says how to start it: exit status 2).
status=0
"$work/prefix/libexec/ballpit/ballpit-model-probe" 2> /dev/null || status=$?
[ "$status" = 2 ] || fail "the installed model probe answered $status, not 2 (usage)" /dev/null

cp -r "$source/examples/hello_pit" "$work/src"
cmake -S "$work/src" -B "$work/hello" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_CXX_COMPILER="$cxx" > "$work/configure.log" 2>&1 ||
  fail "configuring hello_pit against the package failed" "$work/configure.log"
cmake --build "$work/hello" > "$work/build.log" 2>&1 || fail "building hello_pit failed" "$work/build.log"
# The package told the program where its probe lies.
grep -rqs "BALLPIT_MODEL_PROBE=.*$work/prefix/libexec/ballpit/ballpit-model-probe" "$work/hello" ||
  fail "hello_pit was not compiled with the installed probe's path" /dev/null

"$work/hello/hello_pit" 2000 > "$work/hello.txt" 2>&1 || fail "hello_pit failed" "$work/hello.txt"
cat "$work/hello.txt"
example=$(sed -n 's/^state_hash //p' "$work/hello.txt")
cli=$("$ballpit" run --scene pour --set populations.0.count=2000 --set steps=120 --no-progress --no-table |
  sed -n 's/.*"state_hash":"\([0-9a-f]*\)".*/\1/p')
echo "ballpit run: state_hash $cli"
[ -n "$example" ] && [ "$example" = "$cli" ] || fail "hello_pit's state hash '$example' is not ballpit run's '$cli'" /dev/null
grep -q '^escaped 0$' "$work/hello.txt" || fail "balls escaped the pit" "$work/hello.txt"
# The Python module, where the build has one (python/CMakeLists.txt): installed under the
# prefix, it imports from there alone and reaches the same state.
module=$(ls "$work"/prefix/lib*/python3/dist-packages/ballpit.*.so 2> /dev/null | head -n 1)
if [ -n "$module" ]; then
  python=$(PYTHONPATH="$(dirname "$module")" /usr/bin/python3 -c 'import ballpit
s = ballpit.Simulation.from_scene("pour", ["populations.0.count=2000"])
s.step(120)
print(ballpit.__file__, s.report()["state_hash_hex"])' 2> "$work/python.log") || fail "importing the installed Python module failed" "$work/python.log"
  echo "python: $python"
  [ "${python#"$module "}" = "$cli" ] || fail "the installed module's state hash '$python' is not ballpit run's '$cli'" /dev/null
fi
echo "install_package: the installed package builds hello_pit, which matches ballpit run"
