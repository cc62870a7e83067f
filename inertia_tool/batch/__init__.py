"""Many meshes at once: the per-file work and runner (:mod:`.runner`), chunks for the workers (:mod:`.chunks`),
a Dask cluster (:mod:`.cluster`) and the result files (:mod:`.rows`)."""

from .runner import BatchOptions, BatchSummary, analyze_file, discover_files, run_batch

__all__ = ["BatchOptions", "BatchSummary", "analyze_file", "discover_files", "run_batch"]
