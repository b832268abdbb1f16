#!/usr/bin/env python3
"""Fetches real HDRIs for the benchmarks: CC0 lat-long images from the npm package
@pmndrs/assets, where each is a base64 EXR inside a JavaScript module, decoded to
scenes/assets/NAME.exr.

    python3 tools/fetch_hdri.py [NAME ...] [--version 1.7.0] [--list]

NAME defaults to `park` (512 x 256, a sunlit park). Needs npm; nothing is installed (the
package is unpacked in a temporary folder and removed). Scenes whose environment map is a
parameter take one with a define, for example the open scene under the park's sky:

    target/release/ais render scenes/open.xml -D sky=assets/park.exr
    python3 tools/bench_vs_mitsuba.py scenes/open.xml --define sky=assets/park.exr
"""
import argparse
import base64
import os
import re
import subprocess
import sys
import tarfile
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ASSETS = os.path.join(ROOT, "scenes", "assets")
PACKAGE = "@pmndrs/assets"
EMBEDDED_EXR = re.compile(r"data:application/exr;base64,([A-Za-z0-9+/=]+)")


def fail(message):
    """Stops with `message` and a non-zero exit."""
    print(f"fetch_hdri: {message}", file=sys.stderr)
    sys.exit(1)


def unpack_package(version, folder):
    """The package's files, unpacked in `folder` by `npm pack`: its `package` folder."""
    try:
        packed = subprocess.run(["npm", "pack", f"{PACKAGE}@{version}", "--silent", "--pack-destination", folder],
                                capture_output=True, text=True, timeout=600)
    except FileNotFoundError:
        fail("npm not found; install Node.js (npm comes with it)")
    except subprocess.TimeoutExpired:
        fail(f"npm pack {PACKAGE}@{version} took over 10 minutes")
    if packed.returncode != 0:
        fail(f"npm pack {PACKAGE}@{version} failed: {packed.stderr.strip()}")
    tarball = os.path.join(folder, packed.stdout.strip().splitlines()[-1])
    with tarfile.open(tarball) as archive:
        try:
            archive.extractall(folder, filter="data")
        except TypeError:  # a Python without extraction filters (before 3.11.4)
            archive.extractall(folder)
    return os.path.join(folder, "package")


def exr_bytes(module):
    """The EXR file held by the JavaScript module at `module`."""
    with open(module) as f:
        found = EMBEDDED_EXR.search(f.read())
    if found is None:
        fail(f"{module}: no base64 EXR found in it")
    data = base64.b64decode(found.group(1))
    if data[:4] != b"\x76\x2f\x31\x01":
        fail(f"{module}: the decoded data is not an OpenEXR file")
    return data


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    parser.add_argument("names", nargs="*", default=["park"], help="HDRIs to fetch (default: park)")
    parser.add_argument("--version", default="1.7.0", help=f"the version of {PACKAGE}")
    parser.add_argument("--list", action="store_true", help="list the package's HDRIs and stop")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        hdri = os.path.join(unpack_package(args.version, folder), "hdri")
        available = sorted(name[:-len(".exr.js")] for name in os.listdir(hdri) if name.endswith(".exr.js"))
        if args.list:
            print("\n".join(available))
            return
        os.makedirs(ASSETS, exist_ok=True)
        for name in args.names:
            if name not in available:
                fail(f"no HDRI named {name!r} in {PACKAGE}@{args.version}; it has: {', '.join(available)}")
            path = os.path.join(ASSETS, f"{name}.exr")
            data = exr_bytes(os.path.join(hdri, f"{name}.exr.js"))
            partial = path + ".tmp"
            try:
                with open(partial, "wb") as f:
                    f.write(data)
                os.replace(partial, path)  # never a half-written file under the final name
            except OSError as e:
                if os.path.exists(partial):
                    os.remove(partial)
                fail(f"{path}: {e.strerror}")
            print(f"wrote {os.path.relpath(path, ROOT)}")


if __name__ == "__main__":
    main()
