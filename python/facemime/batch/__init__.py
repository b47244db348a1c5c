"""What `facemime batch` is made of: its inputs (:mod:`facemime.batch.inputs`), the manifest of
results (:mod:`facemime.batch.manifest`), the worker that runs one video's task
(:mod:`facemime.batch.worker`) and the Dask cluster (:mod:`facemime.batch.cluster`); the command
itself is :mod:`facemime.app.batch`."""
