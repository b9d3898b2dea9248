#!/bin/sh
# check_table.sh DBC_GEN SOURCE_DIR OUTPUT: the committed tools/python/imdrive/protocol_table.py
# must be what dbc_gen --python writes now from firmware/protocol/messages.hpp.
set -u
dbc_gen=$1; source_dir=$2; output=$3
mkdir -p "$(dirname "$output")" || exit 1
"$dbc_gen" --output /dev/null --python "$output" || exit 1
committed="$source_dir/tools/python/imdrive/protocol_table.py"
if cmp -s "$committed" "$output"; then
  echo "tools/python/imdrive/protocol_table.py is up to date"
  exit 0
fi
diff -u "$committed" "$output" | head -40
echo "tools/python/imdrive/protocol_table.py differs from what dbc_gen writes from"
echo "firmware/protocol/messages.hpp. Regenerate it, from the source directory:"
echo "  $dbc_gen --output /dev/null --python tools/python/imdrive/protocol_table.py"
exit 1
