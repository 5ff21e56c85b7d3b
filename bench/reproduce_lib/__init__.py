"""bench/reproduce_lib — the modules of bench/reproduce (issue 5; split in issue 22).

    config     the scenes, methods, budgets (profiles) and seeds
    run        running tdpm: render (reads the EXR's own figures), compare --json, metrics, scene files
    reference  a scene's render arguments (Settings) and its cached two-half reference
    svg        the montage, the log-log error plot and the profile plot (SVG, PNG by rsvg-convert)
    report     number formatting, runs.csv / sweep.csv, table.md, summary.md (equal-time tables)

Python 3 standard library only; every image measure is `tdpm compare --json`.
"""
