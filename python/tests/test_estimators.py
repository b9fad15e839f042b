# SPDX-License-Identifier: MIT
"""taxel.learn's classifiers as scikit-learn estimators: the protocol, pickling, copies and the
model files. scikit-learn is the oracle where it is installed; taxel does not need it."""
import copy
import multiprocessing
import pickle
import warnings

import numpy as np
import pytest

import taxel
from taxel import learn

CLASSES = [learn.LinearSvm, learn.Knn, learn.Lda, learn.RbfSvm, learn.Mlp]

# Checks of sklearn.utils.estimator_checks.check_estimator that are skipped, and why.
SKIPPED = {
    # Knn breaks a tie in votes towards the class of the nearest neighbour among the tied, where
    # scikit-learn expects the first of the tied in classes_ (argmax of predict_proba). On the
    # check's 300 samples one tie differs.
    ("Knn", "check_classifiers_train"): "ties in votes go to the nearest neighbour's class",
}


def blobs(rng, n=60, classes=3, dims=4, labels=None):
    y = np.arange(n) % classes
    centres = rng.normal(scale=4.0, size=(classes, dims))
    x = centres[y] + rng.normal(size=(n, dims))
    if labels is not None:
        y = np.asarray(labels)[y]
    return x, y


def _checks():
    sk = pytest.importorskip("sklearn.utils.estimator_checks")
    out = []
    for cls in CLASSES:
        for est, check in sk.check_estimator(cls(), generate_only=True):
            name = getattr(check, "func", check).__name__
            out.append(pytest.param(est, check, id=f"{cls.__name__}-{name}"))
    return out


try:
    import sklearn  # noqa: F401

    ESTIMATOR_CHECKS = _checks()
except ImportError:  # the tests below skip themselves
    ESTIMATOR_CHECKS = []


@pytest.mark.parametrize("estimator, check", ESTIMATOR_CHECKS)
def test_check_estimator(estimator, check):
    name = getattr(check, "func", check).__name__
    reason = SKIPPED.get((type(estimator).__name__, name))
    if reason:
        pytest.skip(reason)
    from sklearn.exceptions import SkipTestWarning  # noqa: F401 - scikit-learn is there

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            check(estimator)
        except Exception as e:  # scikit-learn's own SkipTest: pandas missing, and the like
            if type(e).__name__ == "SkipTest":
                pytest.skip(str(e))
            raise


def test_the_skipped_checks_still_fail():
    """A skipped check that passes again should leave the list."""
    sk = pytest.importorskip("sklearn.utils.estimator_checks")
    for (cls_name, check_name), _ in SKIPPED.items():
        est = getattr(learn, cls_name)()
        for e, check in sk.check_estimator(est, generate_only=True):
            if getattr(check, "func", check).__name__ == check_name:
                with warnings.catch_warnings(), pytest.raises(AssertionError):
                    warnings.simplefilter("ignore")
                    check(e)
                break


def test_clone_and_cross_val_score(rng):
    base = pytest.importorskip("sklearn.base")
    selection = pytest.importorskip("sklearn.model_selection")
    x, y = blobs(rng, n=90)
    svm = learn.LinearSvm(C=0.5, bias=1.0)
    twin = base.clone(svm)
    assert twin is not svm and twin.get_params() == svm.get_params()
    assert base.is_classifier(svm)
    scores = selection.cross_val_score(svm, x, y, cv=3)
    assert scores.shape == (3,) and scores.min() > 0.9
    grid = selection.GridSearchCV(learn.Knn(), {"k": [1, 3, 5]}, cv=3).fit(x, y)
    assert grid.best_params_["k"] in (1, 3, 5)
    pipeline = pytest.importorskip("sklearn.pipeline")
    preprocessing = pytest.importorskip("sklearn.preprocessing")
    pipe = pipeline.make_pipeline(preprocessing.StandardScaler(), learn.Mlp(epochs=30)).fit(x, y)
    assert pipe.score(x, y) > 0.9


def test_params():
    svm = learn.LinearSvm()
    assert svm.set_params(C=2.0, loss="l1") is svm
    assert svm.get_params()["C"] == 2.0 and svm.loss == "l1"
    assert repr(svm) == "LinearSvm(C=2.0, loss='l1')"
    with pytest.raises(ValueError, match="Invalid parameter 'c' for LinearSvm; valid parameters: C,"):
        svm.set_params(c=1.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'gama'"):
        learn.RbfSvm(gama=1.0)
    assert repr(learn.Mlp(hidden=(8, 4))) == "Mlp(hidden=(8, 4))"


@pytest.mark.parametrize("labels", [[3, 1, 2], ["cat", "ant", "bee"], [2.0, -1.0, 7.0], [2**40, 5, -(2**35)]])
def test_classes_sorted_whatever_their_kind(rng, labels):
    x, y = blobs(rng, labels=labels)
    for cls in CLASSES:
        m = cls().fit(x, y)
        np.testing.assert_array_equal(m.classes_, np.sort(labels))
        scores = m.decision_function(x)
        assert scores.shape == (len(y), 3)
        assert set(m.predict(x)) <= set(labels)
        if cls is not learn.Knn:  # Knn's ties (see SKIPPED)
            np.testing.assert_array_equal(m.predict(x), m.classes_[scores.argmax(axis=1)])


@pytest.mark.parametrize("first", [0, 1])
def test_binary_outputs_are_shaped_and_signed_as_scikit_learns(rng, first):
    x, y = blobs(rng, n=80, classes=2, labels=[7, 4])
    if first:  # the other label first in the data: nothing may change sign
        x, y = x[1:], y[1:]
    for cls in CLASSES:
        m = cls().fit(x, y)
        np.testing.assert_array_equal(m.classes_, [4, 7])
        d = m.decision_function(x)
        assert d.shape == (len(y),)
        np.testing.assert_array_equal(m.predict(x), np.where(d > 0, 7, 4))
    svm = learn.LinearSvm(bias=1.0).fit(x, y)
    assert svm.coef_.shape == (1, 4) and svm.intercept_.shape == (1,)
    np.testing.assert_allclose(svm.decision_function(x), (x @ svm.coef_.T + svm.intercept_)[:, 0], atol=1e-12)
    # The mean of class 7 lies on the positive side.
    assert (x[y == 7].mean(axis=0) @ svm.coef_[0] + svm.intercept_[0]) > 0
    for cls in (learn.Knn, learn.Mlp):
        p = cls().fit(x, y).predict_proba(x)
        assert p.shape == (len(y), 2)
        np.testing.assert_allclose(p.sum(axis=1), 1.0)


def test_not_fitted_and_bad_labels(rng):
    x, y = blobs(rng)
    for cls in CLASSES:
        with pytest.raises(learn.NotFittedError, match="not fitted"):
            cls().predict(x)
        with pytest.raises(ValueError, match="Unknown label type: continuous"):
            cls().fit(x, y + 0.5)
        with pytest.raises(ValueError, match="1 class"):
            cls().fit(x, np.zeros(len(y)))
        with pytest.raises(TypeError, match="sparse"):
            sparse = pytest.importorskip("scipy.sparse")
            cls().fit(sparse.csr_matrix(x), y)


def _equal_models(a, b, x):
    np.testing.assert_array_equal(a.classes_, b.classes_)
    np.testing.assert_array_equal(a.predict(x), b.predict(x))
    np.testing.assert_array_equal(a.decision_function(x), b.decision_function(x))


@pytest.mark.parametrize("cls", CLASSES)
def test_pickle_deepcopy_and_bytes_round_trip(rng, cls, tmp_path):
    x, y = blobs(rng)
    m = cls().fit(x, y)
    for other in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m), copy.copy(m), cls.from_bytes(m.to_bytes())):
        _equal_models(m, other, x)
    unfitted = pickle.loads(pickle.dumps(cls(seed=5) if "seed" in cls().get_params() else cls()))
    assert unfitted.get_params() == (cls(seed=5) if "seed" in cls().get_params() else cls()).get_params()
    # The compiled model pickles on its own too.
    raw = pickle.loads(pickle.dumps(m.model_))
    np.testing.assert_array_equal(raw.decision_function(x), m.model_.decision_function(x))
    if cls is not learn.LinearSvm:  # LinearSvm's save writes LIBLINEAR's format (test_learn)
        path = tmp_path / "model.txm"
        m.save(path)
        _equal_models(m, cls.load(path), x)
        damaged = path.read_bytes()[:-3]
        path.write_bytes(damaged)
        with pytest.raises(taxel.IoError, match="model.txm: byte .*(cut short|bytes left hold)"):
            cls.load(path)
    # A model of string labels pickles, but has no integer file form.
    s = cls().fit(x, np.array(["a", "b", "c"])[y])
    _equal_models(s, pickle.loads(pickle.dumps(s)), x)
    with pytest.raises(ValueError, match="integer labels"):
        s.to_bytes()


def test_pickled_state_version_is_checked(rng):
    x, y = blobs(rng)
    state = learn.Lda().fit(x, y).__getstate__()
    state["_taxel_state_version"] = 99
    with pytest.raises(ValueError, match="version 99"):
        learn.Lda().__setstate__(state)
    with pytest.raises(taxel.IoError, match="holds a Lda, not a Knn"):
        learn.Knn.from_bytes(learn.Lda().fit(x, y).to_bytes())


def _predict_in_worker(blob, x):
    return pickle.loads(blob).predict(x)


def test_a_pickled_model_predicts_the_same_in_another_process(rng):
    x, y = blobs(rng, n=90)
    models = [cls().fit(x, y) for cls in CLASSES]
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        got = pool.starmap(_predict_in_worker, [(pickle.dumps(m), x) for m in models])
    for m, p in zip(models, got):
        np.testing.assert_array_equal(p, m.predict(x))


def test_liblinear_files_keep_working(rng, tmp_path):
    x, y = blobs(rng, labels=[5, 9, 2])
    svm = learn.LinearSvm(bias=1.0).fit(x, y)
    path = tmp_path / "model.txt"
    svm.save(path)
    again = learn.LinearSvm.load(path)
    assert again.bias == 1.0
    _equal_models(svm, again, x)
    np.testing.assert_array_equal(learn.LinearSvm.from_liblinear(svm.to_liblinear()).coef_, svm.coef_)
