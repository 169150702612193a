#!/usr/bin/env bash
# `cpack -G DEB` makes a Debian package that dpkg-deb reads: named hapticsim, its library
# dependencies found by dpkg-shlibdeps (LCM among them), the config a conffile, maintainer scripts
# that parse; unpacked, the unit starts /usr/bin/hapticsimd with /etc/hapticsim/hapticsimd.toml,
# the unpacked daemon checks the unpacked config, and the Python types import from where Debian's
# python3 looks. (Installing it with dpkg and starting the service needs a machine of its own
# with systemd running: not done here, where the suite must leave the host as it found it.)
# Usage: deb_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1 work=$2
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work"
mkdir -p "$work"
(cd "$work" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work" > "$work/cpack.log" 2>&1) \
  || { cat "$work/cpack.log"; fail "cpack -G DEB"; }
deb=$(ls "$work"/*.deb)
echo "== $(basename "$deb")"
dpkg-deb --info "$deb" > "$work/info"
cat "$work/info"
grep -q "^ Package: hapticsim$" "$work/info" || fail "not named hapticsim"
grep -q "^ Depends: .*liblcm1" "$work/info" || fail "LCM is not among its dependencies"
grep -q "^ Architecture: amd64$" "$work/info" || fail "not amd64"

dpkg-deb -e "$deb" "$work/control"
grep -qx "/etc/hapticsim/hapticsimd.toml" "$work/control/conffiles" || fail "the config is not a conffile"
for script in postinst prerm postrm; do
  [ -x "$work/control/$script" ] || fail "no executable $script"
  sh -n "$work/control/$script" || fail "$script does not parse"
done
grep -q "systemctl enable hapticsimd.service" "$work/control/postinst" || fail "postinst does not enable the service"

dpkg-deb -x "$deb" "$work/root"
root=$work/root
for f in usr/bin/hapticsimd usr/bin/hapticsim usr/lib/libhapticsim_client.so usr/include/hapticsim_client.h \
         usr/lib/systemd/system/hapticsimd.service usr/lib/sysusers.d/hapticsim.conf \
         etc/hapticsim/hapticsimd.toml usr/lib/python3/dist-packages/hapticsim/__init__.py \
         usr/lib/cmake/hapticsim/hapticsimConfig.cmake; do
  [ -e "$root/$f" ] || fail "/$f is not in the package"
done
[ ! -e "$root/usr/lib/python3/dist-packages/hapticsim/__pycache__" ] || fail "a __pycache__ is in the package"
grep -qx "ExecStart=/usr/bin/hapticsimd --config /etc/hapticsim/hapticsimd.toml" \
  "$root/usr/lib/systemd/system/hapticsimd.service" \
  || fail "the unit does not start /usr/bin/hapticsimd: $(grep ExecStart "$root/usr/lib/systemd/system/hapticsimd.service")"
"$root/usr/bin/hapticsimd" --config "$root/etc/hapticsim/hapticsimd.toml" --check-config \
  || fail "the packaged daemon does not accept the packaged config"
PYTHONPATH=$root/usr/lib/python3/dist-packages python3 -c "import hapticsim; hapticsim.status_t().encode()" \
  || fail "the packaged Python types do not import"
echo "PASS"
