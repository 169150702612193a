#!/usr/bin/env bash
# The package as a simulator's build uses it: `cmake --install` into a fresh prefix, then, from
# that prefix only, examples/client/ (a separate CMake project: find_package(hapticsim)), the C
# example again through pkg-config, and examples/python/press.py through the C API with ctypes,
# each pressing a daemon started from the prefix with the installed default config and a shm
# socket of its own. The installed unit passes `systemd-analyze verify` as installed.
# Run inside a private network namespace (the daemon publishes on LCM).
# Usage: install_test.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
build=$1 source=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
fail() { echo "FAIL: $*"; exit 1; }

echo "== cmake --install --prefix $prefix"
cmake --install "$build" --prefix "$prefix" > "$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
for f in bin/hapticsimd bin/hapticsim bin/hapticsim-shm-client \
         lib/libhapticsim_client.so include/hapticsim_client.h \
         lib/libhapticsim_fem.a lib/libhapticsim_scene.a lib/libhapticsim_trial.a \
         lib/libhapticsim_regions.a lib/libhapticsim_errormap.a lib/libhapticsim_ipc.a \
         include/hapticsim/ipc/shm_device_client.hpp include/hapticsim/core/scene/scene.hpp \
         include/hapticsim/rt/seqlock_slot.hpp include/hapticsim/core/error.hpp \
         include/hapticsim/force_feedback_t.hpp \
         lib/cmake/hapticsim/hapticsimConfig.cmake lib/cmake/hapticsim/hapticsimConfigVersion.cmake \
         lib/pkgconfig/hapticsim-client.pc lib/cmake/hapticsim/hapticsimCoreTargets.cmake \
         lib/systemd/system/hapticsimd.service lib/sysusers.d/hapticsim.conf \
         etc/hapticsim/hapticsimd.toml share/doc/hapticsim/README.md \
         share/doc/hapticsim/docs/operations.md; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done
# The LCM types in C (headers and library) and Python (where Debian's python3 looks).
for f in include/hapticsim_status_t.h include/hapticsim_force_feedback_t.h lib/libhapticsim_lcmtypes_c.a; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done
python_dir=$(ls -d "$prefix"/lib/python3*/dist-packages 2>/dev/null | head -1)
[ -n "$python_dir" ] && [ -e "$python_dir/hapticsim/force_feedback_t.py" ] || fail "the Python LCM types are not installed"
PYTHONPATH=$python_dir python3 -c "
import hapticsim
f = hapticsim.force_feedback_t(); f.seq = 7
assert hapticsim.force_feedback_t.decode(f.encode()).seq == 7" || fail "the installed Python LCM types do not import and round-trip"
if [ -e "$build/lcmtypes/hapticsim-lcmtypes.jar" ]; then  # built when a JDK was found
  [ -e "$prefix/share/java/hapticsim-lcmtypes.jar" ] || fail "the lcm-spy jar is not installed"
fi
for f in include/hapticsim/ipc/control_client.hpp include/hapticsim/core/errormap/error_sweep.hpp \
         include/hapticsim/core/scene/scene_toml.hpp; do
  [ ! -e "$prefix/$f" ] || fail "$f is installed, but its library is not"
done
# An install never overwrites the administrator's config: the defaults go beside it.
echo "# edited" >> "$prefix/etc/hapticsim/hapticsimd.toml"
cmake --install "$build" --prefix "$prefix" > "$work/install-again.log"
grep -q "^# edited" "$prefix/etc/hapticsim/hapticsimd.toml" || fail "a second install overwrote the edited config"
cmp -s "$prefix/etc/hapticsim/hapticsimd.toml.default" "$build/packaging/hapticsimd.toml" \
  || fail "the defaults were not put beside the kept config"
# Only the C API leaves the shared library (hapticsim::ipc is inside it, hidden).
exported=$(nm -D --defined-only "$prefix/lib/libhapticsim_client.so" | awk '{ print $3 }' | sort)
others=$(echo "$exported" | grep -v '^hapticsim_' || true)
[ -z "$others" ] || fail "libhapticsim_client.so exports more than the C API: $others"
echo "$exported" | grep -qx hapticsim_send_pose || fail "hapticsim_send_pose is not exported"

echo "== the installed unit and config"
unit=$prefix/lib/systemd/system/hapticsimd.service
grep -qF "ExecStart=$prefix/bin/hapticsimd --config $prefix/etc/hapticsim/hapticsimd.toml" "$unit" \
  || fail "the unit does not start the installed daemon with the installed config: $(grep ExecStart "$unit")"
out=$(systemd-analyze verify "$unit" 2>&1) || fail "systemd-analyze verify: $out"
[ -z "$out" ] || fail "systemd-analyze verify: $out"
"$prefix/bin/hapticsimd" --config "$prefix/etc/hapticsim/hapticsimd.toml" --check-config \
  || fail "the installed default config does not check"

echo "== examples/client against the prefix (find_package)"
cmake -S "$source/examples/client" -B "$work/example" -G Ninja \
      -DCMAKE_PREFIX_PATH="$prefix" > "$work/example-configure.log" 2>&1 \
  || { cat "$work/example-configure.log"; fail "configuring examples/client"; }
cmake --build "$work/example" > "$work/example-build.log" 2>&1 \
  || { cat "$work/example-build.log"; fail "building examples/client"; }

echo "== press.c through pkg-config"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
cc -std=c11 -Wall -Werror "$source/examples/client/press.c" -o "$work/press_c_pkgconfig" \
   $(pkg-config --cflags --libs hapticsim-client) -lm -Wl,-rpath,"$(pkg-config --variable=libdir hapticsim-client)" \
  || fail "press.c does not build with pkg-config's flags"

echo "== a daemon from the prefix"
mkdir -m 0700 "$work/run"
socket=$work/run/hapticsimd.sock
# The installed defaults with shared memory enabled (the device input follows it) and both
# sockets here.
sed -e "/^\[shm\]/,/^\[/ { s|^enabled = .*|enabled = true|; s|^socket = .*|socket = \"$socket\"| }" \
    -e "/^\[control\]/,/^\[/ s|^socket = .*|socket = \"$work/run/control.sock\"|" \
    "$prefix/etc/hapticsim/hapticsimd.toml" > "$work/hapticsimd.toml"
for line in "socket = \"$socket\"" "socket = \"$work/run/control.sock\""; do
  grep -qF "$line" "$work/hapticsimd.toml" || fail "could not set '$line' in the installed config"
done
"$prefix/bin/hapticsimd" --config "$work/hapticsimd.toml" > "$work/daemon.log" 2>&1 &
daemon=$!
trap 'kill $daemon 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -S "$socket" ] && break; sleep 0.1; done
[ -S "$socket" ] || { cat "$work/daemon.log"; fail "the installed daemon did not open $socket"; }

run() {  # run NAME COMMAND...: it must exit 0 and say it felt the press
  echo "-- $1"
  local status=0
  "${@:2}" > "$work/$1.out" 2>&1 || status=$?
  cat "$work/$1.out"
  [ $status -eq 0 ] || { cat "$work/daemon.log"; fail "$1 exited $status"; }
}
run press_c "$work/example/press_c" --socket "$socket"
run press_cpp "$work/example/press_cpp" --socket "$socket"
run press_c_pkgconfig "$work/press_c_pkgconfig" --socket "$socket"
run press_py python3 "$source/examples/python/press.py" --socket "$socket" \
    --library "$prefix/lib/libhapticsim_client.so"
grep -q "in contact; peak force" "$work/press_py.out" || fail "press.py said nothing of the press"

# A wrong socket: a clear reason, exit 2.
status=0
"$work/example/press_c" --socket "$work/run/nothing.sock" > "$work/refused.out" 2>&1 || status=$?
[ $status -eq 2 ] || fail "press_c without a daemon exited $status, not 2"
grep -q "^press_c: cannot connect to hapticsimd at $work/run/nothing.sock" "$work/refused.out" || fail "no reason given: $(cat "$work/refused.out")"

kill -TERM $daemon
wait $daemon || fail "the installed daemon did not stop cleanly: $(tail -5 "$work/daemon.log")"
trap - EXIT
echo "PASS"
