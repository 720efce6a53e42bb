"""Reproduce the Song–Lee Table 1 comparison: 90 min due east at Mach 1, 500 Hz IMU,
3 samples per update, exact increments (docs/validation.md §"Song–Lee Table 1"). Prints the
final position errors beside the paper's and optionally plots them (matplotlib, optional).

    python python/examples/songlee_table1.py [--plot table1.png]
"""

import argparse

import numpy as np

import sdins

# Song & Lee, Table 1: final position errors N, E, D [m] after 5400 s (magnitudes)
PAPER = {"savage": (3.0, 47.1, 557.2), "songlee": (0.01, 0.7, 7.8)}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--plot", help="write a figure of |position error| to this file")
    ap.add_argument("--every-s", type=float, default=10.0, help="output epoch spacing [s]")
    a = ap.parse_args()
    res = sdins.run("mach1-east", algos=["savage", "songlee", "songlee-complete"], every_s=a.every_s)
    print(f"{'algorithm':18} {'pos N m':>12} {'pos E m':>12} {'pos D m':>12}   paper |N| |E| |D|")
    for name, r in res.items():
        p = r.final["pos_err_ned_m"]
        ref = PAPER.get(name)
        ref_s = "   " + " ".join(f"{x:g}" for x in ref) if ref else ""
        print(f"{name:18} {p[0]:12.4e} {p[1]:12.4e} {p[2]:12.4e}{ref_s}")
    if a.plot:
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            raise SystemExit("--plot needs matplotlib: pip install matplotlib")
        fig, axes = plt.subplots(1, 3, figsize=(15, 4), sharex=True)
        for name, r in res.items():
            e = r.errors
            for k, ax in enumerate(axes):
                ax.semilogy(e.t_s, np.abs(e.pos_err_ned_m[:, k]) + 1e-16, label=name)
        for k, ax in enumerate(axes):
            ax.set_title(f"|position error {'NED'[k]}| [m]")
            ax.set_xlabel("time [s]")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
