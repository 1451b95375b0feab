"""crankmodal's figures leave the user's matplotlib alone (backend, pyplot's figures)."""

import subprocess
import sys
import textwrap


def test_a_crankmodal_figure_neither_switches_the_backend_nor_loads_pyplot(tmp_path):
    # In a fresh interpreter, so no other test has imported pyplot before.
    code = textwrap.dedent(f"""
        import sys
        import matplotlib
        matplotlib.use("svg")  # stands for a user's interactive backend
        from crankmodal.plotting import pyplot
        from crankmodal.results import savefig_atomic
        plt = pyplot()
        fig, ax = plt.subplots(1, 2, figsize=(4, 3), sharex=True)
        ax[0].plot([0, 1], [0, 1])
        savefig_atomic(fig, r"{tmp_path / 'f.png'}")
        plt.close(fig)
        print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["svg", "False"], out.stdout + out.stderr
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
