#!/usr/bin/env python3
"""Installs the client library (cmake --install BUILD --component client) into a temporary
prefix and builds tests/client/consumer against the installed files only, twice:
  1. CMake: find_package(mocap_client) -> mocap::mocap_client (version file checked by the
     `0.1` request), configured with CMAKE_PREFIX_PATH=<prefix>;
  2. pkg-config: c++ main.cpp $(pkg-config --cflags --libs mocap-client) with
     PKG_CONFIG_PATH=<prefix>/<libdir>/pkgconfig.
Each consumer binary must run and print "consumer ok". Also checks that nothing installed
names the build or source tree, and that the .pc file's own paths are relative to its
location (${pcfiledir}), so the install can be moved.
"""
import argparse
import glob
import os
import shlex
import subprocess
import sys
import tempfile


def fail(msg):
    print("FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, **kw)
    if r.returncode != 0:
        fail("%s\n%s%s" % (" ".join(cmd), r.stdout[-3000:], r.stderr[-3000:]))
    return r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cmake", required=True)
    ap.add_argument("--build", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--cxx", required=True)
    ap.add_argument("--sanitize", default="", help="MOCAP_SANITIZE of the build (a;b)")
    a = ap.parse_args()
    # A sanitizer build's library is instrumented: the consumer must link the same runtime.
    san = ["-fsanitize=" + a.sanitize.replace(";", ",")] if a.sanitize else []
    consumer = os.path.join(a.source, "tests", "client", "consumer")
    with tempfile.TemporaryDirectory(prefix="mocap_consumer_") as tmp:
        prefix = os.path.join(tmp, "prefix")
        run([a.cmake, "--install", a.build, "--prefix", prefix, "--component", "client"])
        pcs = glob.glob(os.path.join(prefix, "**", "mocap-client.pc"), recursive=True)
        cfgs = glob.glob(os.path.join(prefix, "**", "mocap_clientConfig*.cmake"), recursive=True)
        libs = glob.glob(os.path.join(prefix, "**", "libmocap_client.a"), recursive=True)
        if len(pcs) != 1 or len(cfgs) != 2 or len(libs) != 1:
            fail("installed files: pc %r, config %r, lib %r" % (pcs, cfgs, libs))
        for path in pcs + glob.glob(os.path.join(prefix, "**", "*.cmake"), recursive=True):
            text = open(path).read()
            for tree in (os.path.realpath(a.build), os.path.realpath(a.source)):
                if tree in text:
                    fail("%s names %s" % (path, tree))
        pc_text = open(pcs[0]).read()
        if "-I${includedir}/mocap" not in pc_text or "prefix=${pcfiledir}/" not in pc_text:
            fail("mocap-client.pc is not relative to its own location:\n" + pc_text)

        # 1. find_package
        bdir = os.path.join(tmp, "build_cmake")
        run([a.cmake, "-S", consumer, "-B", bdir, "-DCMAKE_PREFIX_PATH=" + prefix,
             "-DCMAKE_CXX_COMPILER=" + a.cxx, "-DCMAKE_BUILD_TYPE=Release",
             "-DCMAKE_CXX_FLAGS=" + " ".join(san)])
        run([a.cmake, "--build", bdir])
        out = run([os.path.join(bdir, "consumer")])
        if "consumer ok" not in out:
            fail("find_package consumer printed %r" % out)

        # 2. pkg-config
        env = dict(os.environ, PKG_CONFIG_PATH=os.path.dirname(pcs[0]))
        flags = run(["pkg-config", "--cflags", "--libs", "mocap-client"], env=env)
        if prefix not in flags and os.path.realpath(prefix) not in flags:
            fail("pkg-config flags do not point into the prefix: %s" % flags)
        exe = os.path.join(tmp, "consumer_pc")
        run([a.cxx, "-std=c++20", "-O1"] + san + [os.path.join(consumer, "main.cpp"), "-o", exe]
            + shlex.split(flags))
        out = run([exe])
        if "consumer ok" not in out:
            fail("pkg-config consumer printed %r" % out)
    print("ok: find_package and pkg-config consumers built and ran")


if __name__ == "__main__":
    main()
