#!/usr/bin/env bash
# What the Windows binaries of the FMUs need, when it is missing: Debian's
# MinGW-w64 cross compiler and binutils (the linker of the Rust target
# x86_64-pc-windows-gnu, see .cargo/config.toml, and objdump for the DLLs'
# import tables), Wine (runs the Windows test driver against the DLLs,
# tests/test_windows_dll.py), and the Rust target itself.
# Idempotent; needs root or sudo for apt-get on a fresh machine.
set -euo pipefail
need=()
command -v x86_64-w64-mingw32-gcc > /dev/null 2>&1 || need+=(gcc-mingw-w64-x86-64-win32)
command -v x86_64-w64-mingw32-objdump > /dev/null 2>&1 || need+=(binutils-mingw-w64-x86-64)
# the wine package has the `wine` launcher, wine64 the 64-bit loader it runs
command -v wine > /dev/null 2>&1 || need+=(wine)
[ -x /usr/lib/wine/wine64 ] || need+=(wine64)
if [ ${#need[@]} -gt 0 ]; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        sudo="sudo"
    fi
    echo "setup-windows.sh: installing ${need[*]} (Debian packages) for the Windows FMU binaries" >&2
    # Without recommends: wine32 (i386), fonts and GStreamer plug-ins are
    # not needed to run a 64-bit console program.
    install() {
        $sudo env DEBIAN_FRONTEND=noninteractive \
            apt-get install -o DPkg::Lock::Timeout=600 -y -q --no-install-recommends "${need[@]}" > /dev/null
    }
    install || { $sudo apt-get update -o DPkg::Lock::Timeout=600 -q > /dev/null && install; }
fi
command -v x86_64-w64-mingw32-gcc > /dev/null
command -v x86_64-w64-mingw32-objdump > /dev/null
command -v wine > /dev/null
if ! rustup target list --installed | grep -qx x86_64-pc-windows-gnu; then
    echo "setup-windows.sh: adding the Rust target x86_64-pc-windows-gnu" >&2
    rustup target add x86_64-pc-windows-gnu
fi
