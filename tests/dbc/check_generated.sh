#!/bin/sh
# check_generated.sh DBC_GEN SOURCE_DIR WORK_DIR: the committed docs/can/drive.dbc and
# docs/can/messages.md must be what dbc_gen writes now from firmware/protocol/messages.hpp.
set -u
dbc_gen=$1; source_dir=$2; work_dir=$3
mkdir -p "$work_dir" || exit 1
"$dbc_gen" --node 1 --output "$work_dir/drive.dbc" --markdown "$work_dir/messages.md" || exit 1
status=0
for file in drive.dbc messages.md; do
  if cmp -s "$source_dir/docs/can/$file" "$work_dir/$file"; then
    echo "docs/can/$file is up to date"
  else
    diff -u "$source_dir/docs/can/$file" "$work_dir/$file" | head -40
    echo "docs/can/$file differs from what dbc_gen writes from firmware/protocol/messages.hpp."
    status=1
  fi
done
if [ "$status" -ne 0 ]; then
  echo "Regenerate both, from the source directory:"
  echo "  $dbc_gen --node 1 --output docs/can/drive.dbc --markdown docs/can/messages.md"
fi
exit "$status"
