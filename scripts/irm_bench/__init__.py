"""The project's benchmark (`bash scripts/benchmark.sh`): drives x configs, printed as tables.

Layout:
- `cli.py`: the command line (`python3 -m irm_bench`, what scripts/benchmark.sh runs); one
  flag per mode, made from the registry.
- `registry.py`: every table module, in print order, and the modes (a mode is the set of
  tables one run prints: `all` by default, `--quick`, `--long`, `--fleet-passes`, ...).
- `drives.py`: the drives (synthetic scenarios and their variants, generated and cached by
  content; the real-geometry data under ../shared, read in place).
- `configs.py`: the mapper configs (config/ablations/, and the ones written per drive with a
  YAML library: the true extrinsic, the odometry's noise told).
- `runners.py`: generate_drive, map_from_bag and evaluate_map runs, `--jobs` at a time.
- `plan.py`: a run's maps, deduplicated by (drive, config) and run once for every table.
- `report.py`: the tables as text and as Markdown (`--write-docs` rewrites the generated
  sections of docs/benchmark.md); `metrics.py`: figures read from evaluate_map's metrics.
- `targets.yaml` + `targets.py`: the target rows (data), each with its measured figure.
- `tables/`: one module per table (or a group of tables that share their maps).

Adding a table: write `tables/<name>.py` with
    TITLE = "..."                 # what docs/benchmark.md calls its section
    MODES = ("all",)              # the modes that print it ("all" = the default run)
    def requests(ctx): ...        # the maps it needs: [plan.Request(drive, config), ...]
    def tables(ctx, results): ... # [report.Table(title, header, rows), ...]
and add one line to `registry.TABLES`. A new mode is a name in some table's MODES plus its
help line in `registry.MODE_HELP` (then `--<mode>` exists). Figures are measured here and
printed; nothing is asserted (the tests assert loose bounds).
"""
