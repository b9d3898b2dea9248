#!/bin/sh
# run.sh DBC_PATH CANDUMP_LOG [--csv OUT] [--expect EXPECTED_CSV]
# Decodes a candump -L log with a DBC file through candied, a third-party DBC parser
# (decode_log.mjs says how). Installs what is missing first: Node.js and npm with apt-get (when
# root), candied with npm ci from the committed package-lock.json. Exits 1, saying why, when
# that is not possible: the check never passes without having run.
set -eu
here=$(cd "$(dirname "$0")" && pwd)

fail() {
  echo "dbc_check: $*" >&2
  exit 1
}

install_node() {
  [ "$(id -u)" -eq 0 ] ||
    fail "node and npm are needed: apt-get install nodejs npm (or run tools/install_deps.sh)"
  echo "dbc_check: installing nodejs and npm" >&2
  apt-get update -qq >&2 &&
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm >&2 ||
    fail "apt-get install nodejs npm failed"
}

# Whether node_modules holds the candied version that package.json pins.
candied_installed() {
  node -e '
    const read = (path) => JSON.parse(require("fs").readFileSync(path, "utf8"));
    const dir = process.argv[1];
    const pinned = read(dir + "/package.json").dependencies.candied;
    process.exit(read(dir + "/node_modules/candied/package.json").version === pinned ? 0 : 1);
  ' "$here" 2>/dev/null
}

command -v node >/dev/null 2>&1 || install_node
if ! candied_installed; then
  command -v npm >/dev/null 2>&1 || install_node
  echo "dbc_check: installing candied (npm ci --prefix $here)" >&2
  npm ci --prefix "$here" --no-audit --no-fund >&2 || fail "npm ci in $here failed"
  candied_installed || fail "candied is still missing from $here/node_modules after npm ci"
fi
exec node "$here/decode_log.mjs" "$@"
