"""Error against run time: the table and plot of bench/render_vs_cycles*.sh.

    python3 scripts/error_vs_time_plot.py RESULTS.csv TABLE.md [PLOT.png]

RESULTS.csv columns: scene, renderer (atlas | cycles), setting, seconds, mean_rel, rmse,
cloud_mean_rel, cloud_rmse, cloud_bias. Writes the Markdown table, prints it, and with PLOT.png
draws one log-log panel per scene: Cycles' ladder (the reference row left out) as a line, each Atlas
setting as a marker (square: artistic on; triangle: defaults), the 10% target dashed.
"""
import csv
import sys


def write_table(rows, path):
    with open(path, "w") as f:
        f.write("| scene | renderer | setting | s | mean rel. (Y > 5% mean) | RMSE | cloud mean rel. | cloud RMSE | cloud bias |\n")
        f.write("|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write(f"| {r['scene']} | {r['renderer']} | {r['setting']} | {r['seconds']} | {r['mean_rel']} | {r['rmse']} | "
                    f"{r['cloud_mean_rel']} | {r['cloud_rmse']} | {r['cloud_bias']} |\n")


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = sorted({r["scene"] for r in rows}, key=[r["scene"] for r in rows].index)
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.2 * len(scenes), 3.6), squeeze=False)
    for ax, s in zip(axes[0], scenes):
        cyc = [r for r in rows if r["scene"] == s and r["renderer"] == "cycles" and "reference" not in r["setting"]]
        if cyc:
            ax.loglog([float(r["seconds"]) for r in cyc], [float(r["cloud_mean_rel"]) for r in cyc], "o-",
                      label="Cycles (" + ", ".join(r["setting"].split()[0] for r in cyc) + " spp)")
        for r in cyc:
            ax.annotate(r["setting"].split()[0], (float(r["seconds"]), float(r["cloud_mean_rel"])), fontsize=7)
        for r in (r for r in rows if r["scene"] == s and r["renderer"] == "atlas"):
            mk = "s" if "artistic on" in r["setting"] else ("^" if "defaults" in r["setting"] else "x")
            ax.loglog(float(r["seconds"]), float(r["cloud_mean_rel"]), mk, label="Atlas " + r["setting"].replace("artistic off; ", ""))
        ax.axhline(0.10, color="grey", lw=0.8, ls="--")
        ax.set_title(s)
        ax.set_xlabel("wall seconds (2-core machine)")
        ax.set_ylabel("cloud mean relative luminance error")
        ax.grid(True, which="both", lw=0.3)
    axes[0][-1].legend(fontsize=6, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    print("wrote", path)


def main(argv):
    if len(argv) not in (3, 4):
        raise SystemExit(__doc__)
    rows = list(csv.DictReader(open(argv[1])))
    write_table(rows, argv[2])
    print(open(argv[2]).read())
    if len(argv) == 4:
        plot(rows, argv[3])


if __name__ == "__main__":
    main(sys.argv)
