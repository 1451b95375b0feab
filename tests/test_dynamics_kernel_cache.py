"""The compiled kernel's Numba cache is flushed when a module whose jitted functions it calls
changes (numba keys a cached function on its own file only, numba issue #1833): a stale kernel
would compute the old worn-bore or film formula silently. Run in a subprocess with its own
NUMBA_CACHE_DIR so the suite's cache is left alone."""

import os
import subprocess
import sys
import textwrap


def test_a_changed_dependency_stamp_flushes_the_kernel_cache(tmp_path):
    code = textwrap.dedent("""
        import hashlib, pathlib
        import crankmodal.dynamics.kernel.compiled as c
        from crankmodal.dynamics.model import clearance
        from crankmodal.dynamics.laws import lubrication
        from crankmodal.dynamics.laws import reynolds
        from crankmodal.dynamics.model import joints
        cached = [f for f in vars(c).values()
                  if getattr(f, "_cache", None) is not None and hasattr(f, "py_func")]
        stamp = pathlib.Path(cached[0]._cache._cache_path) / "compiled.deps"
        digest = hashlib.sha256(b"".join(pathlib.Path(m.__file__).read_bytes()
                                         for m in (clearance, lubrication, reynolds,
                                                   joints))).hexdigest()
        assert stamp.read_text() == digest          # written at the first import
        assert c._flush_if_dependencies_changed() is False
        # a kernel entry in the index, then an edit of lubrication.py (its stamp changes)
        f = cached[0]
        f._cache._cache_file.save(("key",), "payload")
        assert f._cache._cache_file._load_index()
        stamp.write_text("stale")
        assert c._flush_if_dependencies_changed() is True
        assert f._cache._cache_file._load_index() == {}
        assert stamp.read_text() == digest
        print("ok", len(cached))
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         timeout=300, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("ok")
