#!/bin/sh
# check_deb.sh BUILD_DIR WORK_DIR: makes the Debian package of the build tree with cpack,
# extracts it with dpkg-deb -x into a scratch root, and runs the installed tools from there:
# every tool's --version (the build's), the package's description, the installed README's and
# docs' relative links, the Python command line under a prefix other than /usr, a short
# scenario of the installed data with a plot, and a check that drive_sim runs the installed
# plot script, not the source tree's.
set -eu
build=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
fail() { echo "check_deb: $*"; exit 1; }

if ! cpack --config "$build/CPackConfig.cmake" -B "$work/package" -G DEB > "$work/cpack.log" 2>&1; then
  cat "$work/cpack.log"; fail "cpack failed"
fi
set -- "$work"/package/imdrive_*.deb
[ -f "$1" ] || fail "no imdrive_*.deb in $work/package"
deb=$1
dpkg-deb --field "$deb" Package Version Depends Recommends
description=$(dpkg-deb --field "$deb" Description)
case $description in
  *";"*) fail "the package's description has a ';' (a CMake list joined): $description" ;;
esac
dpkg-deb -x "$deb" "$work/root"
root=$work/root/usr

expected=$("$build/bin/drive_sim" --version)
for tool in drive_sim drive_monitor drive_hil dbc_gen drive_model soak scenario_embed; do
  [ -x "$root/bin/$tool" ] || fail "$tool is not installed in usr/bin"
  version=$("$root/bin/$tool" --version) || fail "$tool --version failed"
  [ "$version" = "$expected" ] || fail "$tool --version: $version, the build's is $expected"
done
# The Python tools' text comes from the build's version header (the C++ tools' too, when they
# were compiled: after a new commit it is newer than a tool not rebuilt since).
header=$(sed -n 's/.*kText = "\(.*\)";/\1/p' "$build/generated/imd_version.hpp")
for script in plot_seed000.py plot_seed001.py; do
  version=$(/usr/bin/python3 "$root/share/imdrive/tools/$script" --version) ||
    fail "$script --version failed"
  [ "$version" = "$header" ] || fail "$script --version: $version, the build's header has $header"
done
for file in share/imdrive/can/drive.dbc share/imdrive/motors/seed000.toml \
            share/doc/imdrive/README.md share/doc/imdrive/docs/flashing.md \
            share/doc/imdrive/tools/python/README.md \
            lib/python3/dist-packages/imdrive/__init__.py; do
  [ -s "$root/$file" ] || fail "usr/$file is not installed"
done

# The installed README and docs keep the source tree's layout: every relative link resolves.
/usr/bin/python3 "$(dirname "$0")/../docs/check_doc_links.py" "$root/share/doc/imdrive" \
  > "$work/doc_links.log" || { cat "$work/doc_links.log"; fail "broken links in usr/share/doc/imdrive"; }

# The Python client's command line, run as installed: the scratch root is a prefix other than
# /usr, so it must find ../lib/python3/dist-packages itself.
[ -x "$root/bin/imdrive" ] || fail "imdrive is not installed in usr/bin"
version=$(env -u PYTHONPATH "$root/bin/imdrive" --version) || fail "imdrive --version failed"
[ "$version" = "$header" ] || fail "imdrive --version: $version, the build's header has $header"

# A short run of an installed scenario (its motor is ../motors/seed000.toml), with a plot.
"$root/bin/drive_sim" "$root/share/imdrive/scenarios/seed000_realistic.toml" --duration-s 0.6 \
  --plot "$work/run.png" > "$work/summary.json" || fail "the installed drive_sim failed"
grep -q '"speed_rms_err_rad_s"' "$work/summary.json" || fail "no summary from the installed run"
[ -s "$work/run.png" ] || fail "no plot from the installed run"

# The installed plot script is the one drive_sim runs: a stand-in that says so.
cat > "$root/share/imdrive/tools/plot_seed000.py" <<'STUB'
import sys
open(sys.argv[sys.argv.index("--out") + 1], "w").write("installed script\n")
STUB
"$root/bin/drive_sim" "$root/share/imdrive/scenarios/seed000_realistic.toml" --duration-s 0.6 \
  --plot "$work/stub.png" > /dev/null || fail "the run with the stand-in plot script failed"
[ "$(cat "$work/stub.png")" = "installed script" ] ||
  fail "drive_sim did not run the installed plot script"
echo "check_deb: $(basename "$deb"): installed tools run, version $expected"
