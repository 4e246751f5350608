"""Paper D's methods against their peers, in one run, on the chapter's data (unit A, first seed):

1. Sugeno inference: ``navlib`` ``SugenoFIS`` vs ``simpful`` (product AND, Gaussian MFs) on the genfis2 FIS;
   largest difference and time per 1000 evaluations.
2. ANFIS hybrid learning on identical rules: ``navlib.methods.anfis`` (MATLAB's normalised step and step-size
   rule) vs ``anfis-toolbox`` 0.2.2 ``HybridTrainer`` (fixed learning rate, plain gradient step); consequents
   after the first least-squares pass, training RMSE after the same number of epochs, time.
3. Fish swarm on the same objective (checking RMSE of genfis2's FIS over ra, rb/ra): ours (one batch per
   call) vs ``scikit-opt``'s ``AFSA`` (one fish per call, unbounded, so its points are clipped to the box
   inside the objective) with the same school size and generations; best value, evaluations, time.

Prints a ratio line per comparison: ``<what>_speedup=<peer time / our time>``.
Run: ``.venv/bin/python benchmarks/bench_paper_d.py``.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))  # the peer adapters

import numpy as np  # noqa: E402
from anfis_toolbox.membership import GaussianMF  # noqa: E402
from anfis_toolbox.model import TSKANFIS  # noqa: E402
from anfis_toolbox.optim.hybrid import HybridTrainer  # noqa: E402
from sko.AFSA import AFSA  # noqa: E402

from navlib.methods.anfis import AnfisOptions, anfis  # noqa: E402
from navlib.methods.fish_swarm import FishSwarmParams, minimise  # noqa: E402
from navlib.methods.subclust import genfis2  # noqa: E402
from navlib.studies import accelerometer as D  # noqa: E402
from peers import simpful_system  # noqa: E402


def main():
    p = D.PaperDParams()
    a = D.samples(D.simulate(p, 0), "A")
    a["set"] = D.split(a, p)
    X, y = a[["temperature_c", "output_mg"]].to_numpy(), a["target_mg"].to_numpy()
    tr, ck = (a["set"] == "train").to_numpy(), (a["set"] == "check").to_numpy()
    fis = genfis2(X[tr], y[tr], 0.5)
    print(f"data: {tr.sum()} training samples, genfis2 r=0.5 -> {fis.n_rules} rules")

    # 1. inference
    fs, names = simpful_system(fis)
    Xq = X[:200]
    t = time.perf_counter()
    ours = fis(Xq)
    t_ours = time.perf_counter() - t
    t = time.perf_counter()
    peer = []
    for x in Xq:
        for nm, v in zip(names, x):
            fs.set_variable(nm, float(v))
        peer.append(fs.Sugeno_inference(["y"], verbose=False)["y"])
    t_peer = time.perf_counter() - t
    print(
        f"inference: max |ours - simpful| = {np.max(np.abs(ours - np.array(peer))):.2e} mg; "
        f"per 1000 points ours {1000 * t_ours / len(Xq) * 1000:.2f} ms, simpful {1000 * t_peer / len(Xq) * 1000:.0f} ms"
    )
    print(f"inference_speedup={t_peer / t_ours:.0f}")

    # 2. ANFIS on identical rules
    epochs = 40
    t = time.perf_counter()
    res = anfis(X[tr], y[tr], fis, AnfisOptions(epochs=epochs))
    t_ours = time.perf_counter() - t
    mfs = {
        f"x{i}": [
            GaussianMF(float(fis.centers[r, i]), float(fis.sigmas[r, i]))
            for r in range(fis.n_rules)
        ]
        for i in range(2)
    }
    model = TSKANFIS(mfs, rules=[(r, r) for r in range(fis.n_rules)])
    trainer = HybridTrainer(learning_rate=0.01, epochs=1)
    trainer.fit(model, X[tr], y[tr])
    first = np.asarray(model.consequent_layer.parameters)
    ls_diff = np.max(np.abs(model.predict(X[tr]).ravel() - fis(X[tr])))
    model = TSKANFIS(
        {
            k: [GaussianMF(m.parameters["mean"], m.parameters["sigma"]) for m in v]
            for k, v in {
                f"x{i}": [
                    GaussianMF(float(fis.centers[r, i]), float(fis.sigmas[r, i]))
                    for r in range(fis.n_rules)
                ]
                for i in range(2)
            }.items()
        },
        rules=[(r, r) for r in range(fis.n_rules)],
    )
    t = time.perf_counter()
    HybridTrainer(learning_rate=0.01, epochs=epochs).fit(model, X[tr], y[tr])
    t_peer = time.perf_counter() - t
    rmse_peer = float(np.sqrt(np.mean((model.predict(X[tr]).ravel() - y[tr]) ** 2)))
    print(
        f"anfis: consequent matrix {first.shape}; first-epoch FIS outputs differ from ours by {ls_diff:.2e} mg "
        f"(the peer's premises already took one step, and it adds a 1e-6 ridge)"
    )
    print(
        f"anfis: training RMSE after {epochs} epochs ours {1000 * res.train_rmse.min():.2f} ug (best epoch "
        f"{res.best_epoch}), anfis-toolbox {1000 * rmse_peer:.2f} ug; time ours {t_ours:.2f} s, peer {t_peer:.2f} s"
    )
    print(f"anfis_speedup={t_peer / t_ours:.2f}")

    # 3. fish swarm
    fallback = float(np.sqrt(np.mean((X[ck, 1] - y[ck]) ** 2)))
    obj = D.scm_objective(X[tr], y[tr], X[ck], y[ck], p.max_rules, fallback)
    lo = np.array([p.radius_bounds[0], p.squash_bounds[0]])
    hi = np.array([p.radius_bounds[1], p.squash_bounds[1]])
    sp = FishSwarmParams()
    t = time.perf_counter()
    r = minimise(obj, np.c_[lo, hi], sp, seed=1)
    t_ours = time.perf_counter() - t
    n_peer = [0]

    def one(z):
        n_peer[0] += 1
        return float(obj((lo + np.clip(z, 0, 1) * (hi - lo))[None])[0])

    np.random.seed(1)
    t = time.perf_counter()
    af = AFSA(
        one,
        n_dim=2,
        size_pop=sp.n_fish,
        max_iter=sp.generations,
        max_try_num=sp.try_number,
        step=sp.step,
        visual=sp.visual,
        q=0.98,
        delta=sp.delta,
    )
    bx, by = af.run()
    t_peer = time.perf_counter() - t
    print(
        f"swarm: ours best {1000 * r.fun:.2f} ug at ra={r.x[0]:.3f}, rb/ra={r.x[1]:.3f} with {r.n_evaluations} "
        f"evaluations in {r.n_calls} calls, {t_ours:.1f} s"
    )
    print(
        f"swarm: scikit-opt AFSA best {1000 * float(np.ravel(by)[0]):.2f} ug with {n_peer[0]} evaluations "
        f"(one per call), {t_peer:.1f} s"
    )
    print(f"swarm_speedup={t_peer / t_ours:.2f}")


if __name__ == "__main__":
    main()
