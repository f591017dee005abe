#!/usr/bin/env bash
# Builds the front end into crates/towpath-server/assets/ (committed; embedded by the server).
# Needs Node.js 20+ and npm; installs the locked packages first.
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
node build.mjs "$@"
