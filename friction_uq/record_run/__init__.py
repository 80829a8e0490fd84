"""``friction-uq run``: from one record to the posterior, its propagation and the report
(:mod:`.pipeline`), with what it decides from its inputs (:mod:`.inputs`) and how it names and
writes its outputs (:mod:`.outputs`)."""

# ArviZ first, while the call stack is short: on import it probes for optional backends (jax, numpyro)
# through lazy_loader, which on a miss walks the whole call stack and every loaded module (inspect.stack);
# deep in this package's imports that cost 0.2-0.35 s, here 0.05-0.08 s (python -X importtime)
import arviz_base  # noqa: F401, I001

from .inputs import alternative_nu_priors, hoop_unusable, sliding_velocity_summary
from .outputs import netcdf_bytes, safe_stem, summary_table
from .pipeline import RunResult, run_file
from .run_document import JSON_VARIABLES

__all__ = ["JSON_VARIABLES", "RunResult", "alternative_nu_priors", "hoop_unusable", "netcdf_bytes", "run_file",
           "safe_stem", "sliding_velocity_summary", "summary_table"]

