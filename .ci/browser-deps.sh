#!/bin/sh
# Install what the browser tests need: Debian's chromium (software WebGL through SwiftShader).
# Idempotent: does nothing when /usr/bin/chromium exists. Playwright for Python comes from the
# `test` extra of pyproject.toml; never run `playwright install` (it downloads browsers).
set -eu
if [ -x /usr/bin/chromium ]; then
    echo "browser-deps: /usr/bin/chromium present"
    exit 0
fi
SUDO=""
if [ "$(id -u)" != 0 ]; then
    SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q chromium
/usr/bin/chromium --version
