"""Running many runs at once: on this machine's cores, or on the workers of a Dask
scheduler (the optional `[cluster]` extra). `jobs` says what travels (a spec's text and
options out, result.json and files back), `executors` where jobs run."""
