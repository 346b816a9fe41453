#!/usr/bin/env python3
"""Exit 0 when two results directories hold the same instances and statistics tables, value for
value (NaN equal to NaN, nulls equal to nulls), and the same provenance metadata apart from the
campaign's path; used by ci_image.sh to compare an image's run with this machine's binary's."""
import sys

import pyarrow.parquet as pq

IGNORED = {b"ARROW:schema", b"cryoslosh.campaign_path"}


def main(a: str, b: str) -> int:
    bad = []
    for name in ("instances.parquet", "statistics.parquet"):
        ta, tb = pq.read_table(f"{a}/{name}"), pq.read_table(f"{b}/{name}")
        if ta.schema.remove_metadata() != tb.schema.remove_metadata():
            bad.append(f"{name}: schemas differ")
            continue
        if ta.num_rows != tb.num_rows:
            bad.append(f"{name}: {ta.num_rows} rows against {tb.num_rows}")
            continue
        for col in ta.column_names:
            x, y = ta[col].to_pylist(), tb[col].to_pylist()
            same = all(u == v or (u != u and v != v) for u, v in zip(x, y))
            if not same:
                bad.append(f"{name}: column {col} differs")
        ma = {k: v for k, v in pq.read_metadata(f"{a}/{name}").metadata.items() if k not in IGNORED}
        mb = {k: v for k, v in pq.read_metadata(f"{b}/{name}").metadata.items() if k not in IGNORED}
        if ma != mb:
            keys = sorted(k.decode() for k in ma.keys() | mb.keys() if ma.get(k) != mb.get(k))
            bad.append(f"{name}: metadata differs in {', '.join(keys)}")
    for line in bad:
        print(f"{a} vs {b}: {line}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: same_tables.py RESULTS_DIR_A RESULTS_DIR_B")
    sys.exit(main(sys.argv[1], sys.argv[2]))
