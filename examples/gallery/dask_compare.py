r"""# A comparison on a Dask cluster

`fl.compare(..., client=client)` sends its fits and replicate datasets to a Dask cluster: a laptop's
`LocalCluster` as here, or a scheduler with workers on many machines (`frictionlab compare --scheduler
tcp://HOST:8786`, see [scaling out](../guides/scaling-out.md)). The answer is the same as without the
cluster: only where the work runs changes.
"""

# %%
# A small cluster in this process: two workers of one thread each (``processes=False`` keeps the example
# light; ``processes=True`` gives each worker its own process and so its own CPU core).
import distributed

import frictionlab as fl

cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
client = distributed.Client(cluster)
print(f"{len(client.scheduler_info()['workers'])} workers, {sum(w['nthreads'] for w in client.scheduler_info()['workers'].values())} threads")

# %%
# The comparison on the cluster, and the same without it. What the output shows: the ranking made on the
# cluster (the report names the cluster under its settings) and that the same call without it gives the same
# ranking and the same AIC.
on_cluster = fl.compare(laws=["coulomb", "wear"], datasets=["impact-golf-v28"], equivalence=False, client=client)
here = fl.compare(laws=["coulomb", "wear"], datasets=["impact-golf-v28"], equivalence=False)
columns = ["dataset", "candidate", "rank", "fits", "aic"]
a, b = on_cluster.to_dataframe()[columns], here.to_dataframe()[columns]
print(a[a.dataset != "ALL"].to_string(index=False))
print("the same ranking and AIC without the cluster:", a.equals(b))

# %%
# Close the client and the cluster when done.
client.close()
cluster.close()
