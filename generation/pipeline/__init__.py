"""The plan runner: the layer above plans, render and quality that turns a stimulus plan into clips.

    runner.plan_jobs(plan) -> (jobs, errors)     resolve generators, hash, pick fallbacks
    runner.run_plan(plan, out_dir, ...)           skip what exists, render the rest (process pool or Dask)
    plan_qa.run(plan)                             the quality records of a plan without rendering video

Nothing below this package imports it.
"""
