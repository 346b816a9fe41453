from typing import List, Optional, Tuple

import pyarrow as pa

__version__: str

# instances, statistics (None with [[variants]]), run.json, why untrusted, each variant's
# (name, instances, statistics, run.json), differences (None without [[variants]]).
Results = Tuple[
    Optional[pa.Table],
    Optional[pa.Table],
    str,
    Optional[str],
    List[Tuple[str, pa.Table, pa.Table, str]],
    Optional[pa.Table],
]

def run(
    campaign: str,
    out: Optional[str] = None,
    instances: Optional[int] = None,
    seed: Optional[int] = None,
    sets: List[str] = ...,
    backend: str = "cpu",
    threads: int = 0,
    shard: Optional[str] = None,
    chunk_size: Optional[int] = None,
    force: bool = False,
) -> Results: ...
def merge(dirs: List[str], out: str, force: bool = False) -> Results: ...
def check(campaign: str, sets: List[str] = ...) -> str: ...
def simulate(
    campaign: str, instance: Optional[int] = None, sets: List[str] = ...
) -> Tuple[pa.Table, List[Tuple[str, float]], str]: ...
def replay(dir: str, instance: int) -> Tuple[Optional[pa.Table], List[Tuple[str, float, float]]]: ...
