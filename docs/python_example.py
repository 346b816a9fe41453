# %% [markdown]
# # cryoslosh from Python: run, filter the worst, replay, plot
#
# A notebook-style script (cells marked `# %%`, as Jupyter, VS Code and jupytext read them).
# Run it from the repository root after `pip install` of the wheel (README, "Python"):
#
#     python docs/python_example.py [OUT_DIR]
#
# It runs 200 instances of the MHTB campaign, takes the five highest peak pressures with polars,
# replays the worst one bit for bit and plots its pressure and temperatures with matplotlib
# (OUT_DIR/worst_case.png; default `python_example_out`).

# %%
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt
import polars as pl

import cryoslosh

out = Path(sys.argv[1] if len(sys.argv) > 1 else "python_example_out")
out.mkdir(parents=True, exist_ok=True)
campaign = "campaigns/mhtb_selfpress.toml"

# %% Run the campaign; the results directory is kept for the replay.
result = cryoslosh.run(campaign, instances=200, seed=1, out=out / "mc", force=True)
instances = pl.from_arrow(result.instances)
print(f"{instances.height} instances on {result.run_info['device']}")
stats = pl.from_arrow(result.statistics)
print(
    stats.filter(
        (pl.col("quantity") == "peak_pressure_pa") & pl.col("statistic").is_in(["p50", "p99", "max"])
    ).select("statistic", "value", "ci_low", "ci_high")
)

# %% The five worst instances by peak pressure, with their sampled inputs.
valid = instances.filter(~pl.col("rejected") & ~pl.col("diverged"))
worst = valid.sort("peak_pressure_pa", descending=True).head(5)
print(worst.select("instance", "tank_heat_leak_w", "propellant_fill_fraction", "peak_pressure_pa", "boiloff_kg"))

# %% Replay the worst one: the same engine, its time history, compared with its row.
i = int(worst["instance"][0])
history, diffs = cryoslosh.replay(out / "mc", i)
assert not diffs, f"replay of instance {i} differs from its row: {diffs}"
h = pl.from_arrow(history)
print(f"instance {i}: replay equals its row of instances.parquet bit for bit ({h.height} history rows)")

# %% Plot: pressure and node temperatures of the worst instance against the campaign's spread.
fig, (ax_p, ax_t) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
t_h = h["time_s"] / 3600.0
ax_p.plot(t_h, h["pressure_pa"] / 1e3, color="#D55E00", label=f"instance {i} (worst)")
p99 = valid["peak_pressure_pa"].quantile(0.99)
ax_p.axhline(p99 / 1e3, color="#0072B2", linestyle="--", label="campaign p99 of peak pressure")
ax_p.set_ylabel("ullage pressure (kPa)")
ax_p.legend(loc="lower right")
for column, color in [("ullage_temp_k", "#E69F00"), ("layer_temp_k", "#009E73"), ("bulk_temp_k", "#56B4E9")]:
    ax_t.plot(t_h, h[column], color=color, label=column.removesuffix("_temp_k"))
ax_t.set_xlabel("time (h)")
ax_t.set_ylabel("temperature (K)")
ax_t.legend(loc="center right")
fig.suptitle(f"{campaign}: worst of {instances.height} instances by peak pressure")
png = out / "worst_case.png"
fig.savefig(png, dpi=110)
print(f"wrote {png}")
