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
                  if getattr(f, "_cache", None) is not None
                  and getattr(getattr(f, "py_func", None), "__module__", "") == c.__name__]
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


def test_a_module_flushes_only_its_own_cache_not_the_kernels_it_imports(tmp_path):
    # the loop imports the kernel's functions; its stamp going stale must flush the loop's own
    # cached functions only (flushing the kernel's made every next process compile it again)
    code = textwrap.dedent("""
        import pathlib
        import crankmodal.dynamics.kernel.compiled as c
        import crankmodal.dynamics.kernel.integrator as loop
        own = [f for f in vars(loop).values() if getattr(f, "_cache", None) is not None
               and getattr(f.py_func, "__module__", "") == loop.__name__]
        kernel = c.assemble
        kernel._cache._cache_file.save(("key",), "payload")
        stamp = pathlib.Path(own[0]._cache._cache_path) / "integrator.deps"
        stamp.write_text("stale")
        assert loop._flush_if_dependencies_changed() is True
        assert kernel._cache._cache_file._load_index()   # the kernel's entry is kept
        print("ok", len(own))
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         timeout=600, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("ok")
