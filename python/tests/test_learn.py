# SPDX-License-Identifier: MIT
"""Classifiers against LIBLINEAR's own train/predict tools and numpy recomputations; the 5x2cv
statistic against its formula."""
import os
import shutil
import subprocess

import numpy as np
import pytest

import taxel
from taxel import learn

TRAIN = os.environ.get("TAXEL_LIBLINEAR_TRAIN") or shutil.which("liblinear-train")
PREDICT = os.environ.get("TAXEL_LIBLINEAR_PREDICT") or shutil.which("liblinear-predict")


def blobs(rng, n=60, classes=3, dims=5, spread=1.0):
    centres = rng.normal(scale=3.0, size=(classes, dims))
    y = np.repeat(np.arange(1, classes + 1), n // classes)
    x = centres[y - 1] + rng.normal(scale=spread, size=(len(y), dims))
    order = rng.permutation(len(y))
    return x[order], y[order].astype(np.int32)


@pytest.mark.skipif(not (TRAIN and PREDICT), reason="liblinear-tools not installed")
@pytest.mark.parametrize("options", [[], ["-s", "3", "-c", "0.1"], ["-B", "1", "-c", "4"], ["-w2", "3"]])
@pytest.mark.parametrize("classes", [2, 3])
def test_linear_svm_matches_liblinear(tmp_path, rng, options, classes):
    # Both solvers run to convergence (eps 1e-9): their random coordinate orders differ, so
    # only the optimum is comparable.
    x, y = blobs(rng, classes=classes, spread=1.5)
    data = tmp_path / "train.txt"
    learn.write_libsvm(str(data), x, y)
    model = tmp_path / "model.txt"
    subprocess.run([TRAIN, "-q", "-e", "1e-9", *options, str(data), str(model)], check=True)
    out = tmp_path / "pred.txt"
    subprocess.run([PREDICT, str(data), str(model), str(out)], check=True, capture_output=True)
    theirs = np.loadtxt(out, dtype=int)

    kw = {"eps": 1e-9}
    opts = dict(zip(options[::2], options[1::2]))
    if "-s" in opts:
        kw["loss"] = "l1"
    if "-c" in opts:
        kw["C"] = float(opts["-c"])
    if "-B" in opts:
        kw["bias"] = float(opts["-B"])
    if "-w2" in opts:
        kw["class_weights"] = {2: float(opts["-w2"])}
    ours = learn.LinearSvm(**kw).fit(x, y)
    np.testing.assert_array_equal(ours.predict(x), theirs)
    # Their model file, loaded, gives their weights and predictions.
    loaded = learn.LinearSvm.load(str(model))
    np.testing.assert_array_equal(loaded.predict(x), theirs)
    # Within what LIBLINEAR's 1000-iteration cap leaves of the optimum on the harder problems.
    np.testing.assert_allclose(ours.coef_, loaded.coef_, atol=2e-5)
    # Our model file, read by their predict, gives our predictions.
    mine = tmp_path / "mine.txt"
    ours.save(str(mine))
    out2 = tmp_path / "pred2.txt"
    subprocess.run([PREDICT, str(data), str(mine), str(out2)], check=True, capture_output=True)
    np.testing.assert_array_equal(np.loadtxt(out2, dtype=int), ours.predict(x))


def test_linear_svm_decision_is_linear(rng):
    x, y = blobs(rng, classes=3)
    svm = learn.LinearSvm(bias=1.0).fit(x, y)
    d = svm.decision_function(x)
    np.testing.assert_allclose(d, x @ svm.coef_.T + svm.intercept_, atol=1e-12)
    np.testing.assert_array_equal(svm.predict(x), svm.classes_[d.argmax(axis=1)])
    with pytest.raises(ValueError, match="Reshape your data"):
        svm.predict(x[0])
    again = learn.LinearSvm.from_liblinear(svm.to_liblinear())
    np.testing.assert_array_equal(again.coef_, svm.coef_)


def test_knn_matches_brute_force(rng):
    x, y = blobs(rng, n=90, spread=3.0)
    q = rng.normal(scale=3.0, size=(40, 5))
    knn = learn.Knn(k=5).fit(x, y)
    d = np.linalg.norm(q[:, None, :] - x[None, :, :], axis=2)
    nearest = np.argsort(d, axis=1, kind="stable")[:, :5]
    shares = np.stack([(y[nearest] == c).mean(axis=1) for c in knn.classes_], axis=1)
    np.testing.assert_allclose(knn.decision_function(q), shares)


@pytest.mark.parametrize("model", [learn.LinearSvm(), learn.Knn(), learn.Lda(), learn.RbfSvm(), learn.Mlp(epochs=50)])
def test_every_classifier_fits_and_cross_validates(rng, model):
    x, y = blobs(rng, n=90)
    report = learn.cross_validate(model, x, y, folds=3)
    assert report.accuracy > 0.9
    assert report.confusion.sum() == len(y)
    np.testing.assert_allclose(report.accuracy, (report.predicted == y).mean())
    assert model.fit(x, y) is model
    assert model.decision_function(x).shape == (len(y), 3)


def test_five_by_two_matches_its_formula(rng):
    x, y = blobs(rng, n=120, spread=3.0)
    r = learn.five_by_two_cv(learn.LinearSvm(), learn.Knn(k=1), x, y, seed=3)
    p = r.differences
    s2 = ((p - p.mean(axis=1, keepdims=True)) ** 2).sum(axis=1)
    t = p[0, 0] / np.sqrt(s2.mean())
    assert r.t == pytest.approx(t, rel=1e-12)
    stats = pytest.importorskip("scipy.stats")
    assert r.p_value == pytest.approx(2 * stats.t.sf(abs(t), 5), rel=1e-6)
    assert r.critical == pytest.approx(stats.t.ppf(0.975, 5), rel=1e-6)
    again = learn.five_by_two_t_test(p, 0.05)
    assert again.t == r.t and again.reject == r.reject


def test_errors(tmp_path, rng):
    x, y = blobs(rng)
    bad = x.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        learn.LinearSvm().fit(bad, y)
    with pytest.raises(ValueError, match="not fitted"):
        learn.LinearSvm().predict(x)
    with pytest.raises(ValueError, match="n_samples"):
        learn.LinearSvm().fit(x, y[:-1])
    with pytest.raises(ValueError, match="C = "):
        learn.LinearSvm(C=-1).fit(x, y)
    svm = learn.LinearSvm().fit(x, y)
    with pytest.raises(ValueError, match="X has 3 features, but LinearSvm is expecting 5"):
        svm.predict(x[:, :3])
    with pytest.raises(TypeError, match="classifier"):
        learn.cross_validate(object(), x, y)
    broken = tmp_path / "broken.txt"
    broken.write_text("solver_type L2R_L2LOSS_SVC_DUAL\nnr_class two\n")
    with pytest.raises(taxel.IoError, match="broken.txt:2"):
        learn.LinearSvm.load(str(broken))
    with pytest.raises(OSError):
        learn.LinearSvm.load(str(tmp_path / "missing.txt"))
    with pytest.raises(OSError):
        svm.save(str(tmp_path / "no" / "such" / "dir" / "m.txt"))


def test_threads_do_not_change_results(rng):
    x, y = blobs(rng, n=90, spread=2.5)
    one = learn.cross_validate(learn.Mlp(epochs=20), x, y, folds=5, snr_db=5.0, threads=1)
    two = learn.cross_validate(learn.Mlp(epochs=20), x, y, folds=5, snr_db=5.0, threads=2)
    np.testing.assert_array_equal(one.predicted, two.predicted)
    a = learn.five_by_two_cv(learn.LinearSvm(), learn.Knn(), x, y, threads=1)
    b = learn.five_by_two_cv(learn.LinearSvm(), learn.Knn(), x, y, threads=2)
    np.testing.assert_array_equal(a.differences, b.differences)
    s1 = learn.LinearSvm(threads=1).fit(x, y)
    s3 = learn.LinearSvm(threads=3).fit(x, y)
    assert s1.coef_.shape[0] == len(np.unique(y)) > 2
    np.testing.assert_array_equal(s1.coef_, s3.coef_)
