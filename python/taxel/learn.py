# SPDX-License-Identifier: MIT
"""Classifiers on feature arrays that behave as scikit-learn's estimators do.

``LinearSvm`` reproduces LIBLINEAR 2.3 (``-s 1`` / ``-s 3``, one-vs-rest) and reads and writes
its model files; ``Knn``, ``Lda``, ``RbfSvm`` and ``Mlp`` are its competitors. Each one follows
the scikit-learn estimator protocol without needing scikit-learn: parameters are set in the
constructor and checked by ``fit``; ``get_params`` / ``set_params``, so that
``sklearn.base.clone``, ``cross_val_score``, ``GridSearchCV`` and ``Pipeline`` take them;
``classes_`` sorted; labels of any kind (integers, strings); ``decision_function`` of shape
(n_samples,) for two classes, positive for ``classes_[1]``; ``score`` is the accuracy. Models
pickle and deep-copy; ``to_bytes`` / ``from_bytes`` and ``save`` / ``load`` keep them in
taxel's versioned model format.

``cross_validate``, ``five_by_two_cv`` and ``five_by_two_t_test`` run taxel's own stratified
cross-validation and Dietterich's 5x2cv paired t test on many threads.
"""
from __future__ import annotations

import difflib
import functools
import importlib
import inspect
import os
import sys
import typing
import warnings

import numpy as np
import numpy.typing as npt

# The compiled classifiers (taxel._taxel.learn), typed as Any for the type checker.
_cpp: typing.Any = importlib.import_module("taxel._taxel").learn

if typing.TYPE_CHECKING:

    class CvReport(typing.Protocol):
        """Out-of-fold results of cross_validate."""

        status: str
        message: str
        accuracy: float
        classes: npt.NDArray[np.int32]
        confusion: npt.NDArray[np.int32]
        per_class_accuracy: npt.NDArray[np.float64]
        predicted: npt.NDArray[np.int32]
        fold: npt.NDArray[np.int32]

    class FiveByTwoResult(typing.Protocol):
        """Dietterich's 5x2cv paired t test."""

        status: str
        message: str
        differences: npt.NDArray[np.float64]
        t: float
        p_value: float
        alpha: float
        critical: float
        reject: bool
        mean_error_a: float
        mean_error_b: float

    def five_by_two_t_test(differences: npt.ArrayLike, alpha: float = 0.05) -> FiveByTwoResult:
        """The 5x2cv t statistic, p-value and decision from the (5, 2) error differences."""

    def read_libsvm(path: str) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
        """(X, y) from a LIBSVM/LIBLINEAR data file (OSError naming the line)."""

    def write_libsvm(path: str, X: npt.ArrayLike, y: npt.ArrayLike) -> None:
        """Writes X and y as a LIBSVM data file."""

else:
    CvReport = _cpp.CvReport
    FiveByTwoResult = _cpp.FiveByTwoResult
    five_by_two_t_test = _cpp.five_by_two_t_test
    read_libsvm = _cpp.read_libsvm
    write_libsvm = _cpp.write_libsvm

__all__ = [
    "CvReport",
    "FiveByTwoResult",
    "Knn",
    "Lda",
    "LinearSvm",
    "Mlp",
    "NotFittedError",
    "RbfSvm",
    "cross_validate",
    "five_by_two_cv",
    "five_by_two_t_test",
    "read_libsvm",
    "write_libsvm",
]

_STATE_VERSION = 1
_Array = npt.NDArray[typing.Any]
_INT32 = np.iinfo(np.int32)


class NotFittedError(ValueError, AttributeError):
    """A model was used before ``fit``. When scikit-learn is imported, the error raised is also
    a ``sklearn.exceptions.NotFittedError``."""


def _not_fitted(name: str) -> Exception:
    message = f"This {name} instance is not fitted yet; call fit with training data first."
    sk = sys.modules.get("sklearn.exceptions")
    if sk is not None:
        both = type("NotFittedError", (NotFittedError, sk.NotFittedError), {})
        return typing.cast(Exception, both(message))
    return NotFittedError(message)


def _warn_column_y() -> None:
    sk = sys.modules.get("sklearn.exceptions")
    category = sk.DataConversionWarning if sk is not None else UserWarning
    warnings.warn(
        "A column-vector y was passed when a 1d array was expected; it is read as y.ravel().",
        category,
        stacklevel=3,
    )


def _features(x: typing.Any, name: str, dims: int | None = None) -> npt.NDArray[np.float64]:
    """X as a C-contiguous float64 array (n_samples, n_features), checked as scikit-learn does."""
    if hasattr(x, "toarray") or type(x).__module__.startswith("scipy.sparse"):
        raise TypeError(f"{name} takes dense arrays, not sparse matrices: pass X.toarray()")
    a = np.asarray(x)
    if a.dtype.kind == "c":
        raise ValueError(f"{name}: Complex data not supported")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if a.ndim != 2:
        raise ValueError(
            f"{name}: expected a 2D array (n_samples, n_features), got {a.ndim}D. Reshape your "
            "data with X.reshape(1, -1) for a single sample or X.reshape(-1, 1) for a single "
            "feature"
        )
    for axis, what in ((0, "sample"), (1, "feature")):
        if a.shape[axis] == 0:
            raise ValueError(
                f"{name}: found an array with 0 {what}(s) (shape={a.shape}) while a minimum of 1 "
                "is required."
            )
    if not np.isfinite(a).all():
        raise ValueError(f"{name}: X contains NaN or infinity; every feature must be finite")
    if dims is not None and a.shape[1] != dims:
        raise ValueError(f"X has {a.shape[1]} features, but {name} is expecting {dims} features as input")
    return a


def _targets(y: typing.Any, name: str, n: int) -> _Array:
    if y is None:
        raise ValueError(f"{name} requires y to be passed, but the target y is None")
    a = np.asarray(y)
    if a.ndim == 2 and a.shape[1] == 1:
        _warn_column_y()
        a = a.ravel()
    if a.ndim != 1:
        raise ValueError(f"{name}: y should be a 1d array, got shape {a.shape}")
    if a.shape[0] != n:
        raise ValueError(f"{name}: X has n_samples = {n} but y has {a.shape[0]} labels")
    if a.dtype.kind == "f":
        if not np.isfinite(a).all():
            raise ValueError(f"{name}: Input y contains NaN or infinity")
        fractional = a[a != np.round(a)]
        if fractional.size:
            raise ValueError(
                f"{name}: Unknown label type: continuous (labels are whole numbers or strings; "
                f"got {fractional[0]!r})"
            )
    elif a.dtype.kind not in "biuUSO":
        raise ValueError(f"{name}: Unknown label type: {a.dtype}")
    return a


class _Classifier:
    """What the five classifiers share: the estimator protocol over a compiled model."""

    _estimator_type = "classifier"
    _cpp_name = ""

    # --- parameters -------------------------------------------------------------------------
    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)  # follows __wrapped__ (_keyword_hints)
        return [p.name for p in sig.parameters.values() if p.kind == p.KEYWORD_ONLY]

    def get_params(self, deep: bool = True) -> dict[str, typing.Any]:
        """The constructor's parameters by name (scikit-learn's protocol; `deep` is accepted
        for compatibility and changes nothing: these models hold no other estimators)."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params: typing.Any) -> typing.Self:
        """Sets parameters by name and returns self; they are checked by the next fit."""
        valid = self._param_names()
        for name, value in params.items():
            if name not in valid:
                raise ValueError(
                    f"Invalid parameter {name!r} for {type(self).__name__}; valid parameters: "
                    + ", ".join(valid)
                )
            setattr(self, name, value)
        return self

    def __repr__(self) -> str:
        sig = inspect.signature(type(self).__init__)
        changed = []
        for name in self._param_names():
            value = getattr(self, name)
            default = sig.parameters[name].default
            if not (value is default or (type(value) is type(default) and value == default)):
                changed.append(f"{name}={value!r}")
        return f"{type(self).__name__}({', '.join(changed)})"

    def _make_model(self, code: typing.Callable[[typing.Any], int] = int) -> typing.Any:
        """A new, unfitted compiled model with these parameters (ValueError when one is out of
        range); `code` turns a label into the compiled model's."""
        return getattr(_cpp, self._cpp_name)(**self._cpp_params(code))

    def _cpp_params(self, code: typing.Callable[[typing.Any], int]) -> dict[str, typing.Any]:
        return self.get_params()

    # --- fitting and prediction -------------------------------------------------------------
    def fit(
        self,
        X: npt.ArrayLike,
        y: npt.ArrayLike,
        groups: npt.ArrayLike | None = None,
    ) -> typing.Self:
        """Trains on X (n_samples, n_features) and labels y (integers or strings); returns self.
        ValueError for an empty set, non-finite features, continuous labels or one class;
        RuntimeWarning when an iteration cap stopped training (the model is still usable)."""
        name = type(self).__name__
        x = _features(X, name)
        labels = _targets(y, name, x.shape[0])
        classes, codes = np.unique(labels, return_inverse=True)
        if classes.size < 2:
            raise ValueError(f"{name} needs at least 2 classes; y holds 1 class ({classes[0]!r})")
        integral = labels.dtype.kind in "biuf" and labels.dtype.kind != "b"
        # The compiled model keeps integer labels themselves (its files and reports name them)
        # and others by their position in classes_.
        encoded = not (integral and _INT32.min <= classes[0] and classes[-1] <= _INT32.max)
        targets = (codes if encoded else labels).astype(np.int32)

        def code(label: typing.Any) -> int:
            hit = np.flatnonzero(classes == label)
            if hit.size == 0:
                raise ValueError(f"{name}: class_weights names {label!r}, which y does not hold")
            return int(hit[0]) if encoded else int(classes[hit[0]])

        model = self._make_model(code)
        self._encoded = encoded
        model.fit(x, targets, None if groups is None else np.asarray(groups, dtype=np.int32))
        self._set_model(model, classes)
        return self

    def _set_model(self, model: typing.Any, classes: _Array) -> None:
        labels = np.asarray(model.classes_)
        self._order = np.argsort(labels)
        self._labels = labels[self._order]  # the compiled model's labels, ascending
        self.classes_ = classes
        self.n_features_in_ = int(model.n_features_in_)
        self.model_ = model

    def _fitted(self) -> typing.Any:
        model = self.__dict__.get("model_")
        if model is None:
            raise _not_fitted(type(self).__name__)
        return model

    def _scores(self, X: npt.ArrayLike) -> tuple[typing.Any, _Array]:
        """The compiled model's decision values, columns in classes_ order."""
        model = self._fitted()
        x = _features(X, type(self).__name__, self.n_features_in_)
        return model, np.asarray(model.decision_function(x))[:, self._order]

    def predict(self, X: npt.ArrayLike) -> _Array:
        """The label of each row of X (n_samples,), from classes_."""
        model = self._fitted()
        x = _features(X, type(self).__name__, self.n_features_in_)
        # The compiled model's labels, as positions in classes_ (both ascending).
        raw = np.asarray(model.predict(x))
        position = np.searchsorted(self._labels, raw)
        return typing.cast(_Array, self.classes_[position])

    def decision_function(self, X: npt.ArrayLike) -> _Array:
        """Decision values: (n_samples, n_classes) in classes_ order, or (n_samples,) for two
        classes, positive for classes_[1]."""
        _, scores = self._scores(X)
        if scores.shape[1] == 2:
            return typing.cast(_Array, scores[:, 1] - scores[:, 0])
        return scores

    def score(self, X: npt.ArrayLike, y: npt.ArrayLike) -> float:
        """Mean accuracy of predict(X) against y."""
        return float(np.mean(self.predict(X) == np.asarray(y).ravel()))

    # --- the compiled model's state ---------------------------------------------------------
    def to_bytes(self) -> bytes:
        """The fitted model in taxel's versioned model format (integer labels only; pickle an
        estimator trained on other labels)."""
        model = self._fitted()
        if self._encoded:
            raise ValueError(
                f"{type(self).__name__}.to_bytes keeps integer labels only; this model was "
                "trained on other labels: pickle it instead"
            )
        return typing.cast(bytes, model.to_bytes())

    @classmethod
    def from_bytes(cls, data: bytes, source: str = "") -> typing.Self:
        """An estimator from to_bytes(); taxel.IoError naming `source` for damaged bytes."""
        return cls._from_model(getattr(_cpp, cls._cpp_name).from_bytes(data, source))

    @classmethod
    def _from_model(cls, model: typing.Any) -> typing.Self:
        est = cls()
        est._encoded = False
        if int(model.n_features_in_) > 0:
            est._set_model(model, np.sort(np.asarray(model.classes_)))
        return est

    def save(self, path: str | os.PathLike[str]) -> None:
        """Writes the fitted model to `path` in taxel's model format, atomically (OSError on
        failure)."""
        data = self.to_bytes()
        target = os.fspath(path)
        temporary = f"{target}.tmp{os.getpid()}"
        try:
            with open(temporary, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.replace(temporary, target)
        finally:
            if os.path.exists(temporary):
                os.remove(temporary)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> typing.Self:
        """Reads a model written by save()."""
        with open(path, "rb") as f:
            return cls.from_bytes(f.read(), os.fspath(path))

    # --- pickling ---------------------------------------------------------------------------
    def __getstate__(self) -> dict[str, typing.Any]:
        state = dict(self.__dict__)
        state["_taxel_state_version"] = _STATE_VERSION
        return state

    def __setstate__(self, state: dict[str, typing.Any]) -> None:
        version = state.pop("_taxel_state_version", None)
        if version != _STATE_VERSION:
            raise ValueError(
                f"{type(self).__name__}: pickled state version {version!r} is not supported "
                f"(this taxel reads version {_STATE_VERSION})"
            )
        self.__dict__.update(state)

    def _more_tags(self) -> dict[str, typing.Any]:
        return {"requires_y": True}


class _Probabilistic(_Classifier):
    """Classifiers whose decision values are class probabilities or vote shares."""

    def predict_proba(self, X: npt.ArrayLike) -> _Array:
        """(n_samples, n_classes) probabilities (Mlp) or vote shares (Knn), classes_ order."""
        _, scores = self._scores(X)
        return scores


class LinearSvm(_Classifier):
    """Linear SVM by LIBLINEAR's dual coordinate descent: loss 'l2' (``-s 1``, default) or 'l1'
    (``-s 3``); C (``-c``), eps (``-e``), bias (``-B``, < 0 for none), class_weights
    {label: weight} (``-wi``); threads trains the one-vs-rest problems at once (0: every core;
    the model does not depend on it). ``save`` and ``load`` use LIBLINEAR's model files."""

    _cpp_name = "LinearSvm"

    def __init__(
        self,
        *,
        C: float = 1.0,
        loss: str = "l2",
        eps: float = 0.1,
        bias: float = -1.0,
        max_iterations: int = 1000,
        shrinking: bool = True,
        seed: int = 1,
        class_weights: dict[typing.Any, float] | None = None,
        threads: int = 0,
    ) -> None:
        self.C = C
        self.loss = loss
        self.eps = eps
        self.bias = bias
        self.max_iterations = max_iterations
        self.shrinking = shrinking
        self.seed = seed
        self.class_weights = class_weights
        self.threads = threads

    def _cpp_params(self, code: typing.Callable[[typing.Any], int]) -> dict[str, typing.Any]:
        p = self.get_params()
        p["class_weights"] = {code(k): float(w) for k, w in (self.class_weights or {}).items()}
        return p

    @property
    def coef_(self) -> _Array:
        """(n_classes, n_features) weights in classes_ order; (1, n_features) for two classes,
        positive towards classes_[1]."""
        model = self._fitted()
        w = np.asarray(model.coef_)
        if w.shape[0] == 1:
            return w * self._binary_sign()
        return typing.cast(_Array, w[self._order])

    @property
    def intercept_(self) -> _Array:
        """(n_classes,) intercepts (bias times the bias weight), or (1,) for two classes."""
        model = self._fitted()
        b = np.asarray(model.intercept_)
        if b.shape[0] == 1:
            return b * self._binary_sign()
        return typing.cast(_Array, b[self._order])

    def _binary_sign(self) -> float:
        # LIBLINEAR's single weight vector is positive towards its first label.
        return 1.0 if self._order[0] == 1 else -1.0

    def decision_function(self, X: npt.ArrayLike) -> _Array:
        """Decision values X coef_' + intercept_: (n_samples, n_classes) in classes_ order, or
        (n_samples,) for two classes, positive for classes_[1]."""
        _, scores = self._scores(X)
        if scores.shape[1] == 2:
            return typing.cast(_Array, scores[:, 1])
        return scores

    @property
    def solver_type(self) -> str:
        """LIBLINEAR's name of the solver that trained the model."""
        return typing.cast(str, self._fitted().solver_type)

    @property
    def iterations(self) -> list[int]:
        """Outer iterations per binary problem of the last fit."""
        return list(self._fitted().iterations)

    @property
    def objective(self) -> list[float]:
        """Final dual objective per binary problem of the last fit."""
        return list(self._fitted().objective)

    def to_liblinear(self) -> str:
        """The model as LIBLINEAR model-file text."""
        self.to_bytes()  # integer labels only
        return typing.cast(str, self._fitted().to_liblinear())

    @classmethod
    def from_liblinear(cls, text: str) -> LinearSvm:
        """A fitted model from LIBLINEAR model-file text (any classification solver)."""
        est = cls._from_model(_cpp.LinearSvm.from_liblinear(text))
        est.bias = float(est.model_.bias)
        return est

    def save(self, path: str | os.PathLike[str]) -> None:
        """Writes a LIBLINEAR model file, atomically (OSError on failure). to_bytes() keeps
        every option as well."""
        self.to_bytes()  # integer labels only
        self._fitted().save(os.fspath(path))

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> LinearSvm:
        """Reads a LIBLINEAR model file (any classification solver)."""
        est = cls._from_model(_cpp.LinearSvm.load(os.fspath(path)))
        est.bias = float(est.model_.bias)
        return est


class Knn(_Probabilistic):
    """k nearest neighbours by brute force ('euclidean' or 'manhattan'; votes 'uniform' or by
    1 / 'distance'); decision values and predict_proba are vote shares."""

    _cpp_name = "Knn"

    def __init__(self, *, k: int = 5, metric: str = "euclidean", weighting: str = "uniform") -> None:
        self.k = k
        self.metric = metric
        self.weighting = weighting


class Lda(_Classifier):
    """Linear discriminant analysis with one shared covariance, shrunk towards a multiple of the
    identity by `shrinkage` in [0, 1] (negative: Ledoit-Wolf); class priors from the class
    frequencies when empirical_priors, else uniform."""

    _cpp_name = "Lda"

    def __init__(self, *, shrinkage: float = 0.0, empirical_priors: bool = True) -> None:
        self.shrinkage = shrinkage
        self.empirical_priors = empirical_priors


class RbfSvm(_Classifier):
    """Kernel SVM with K = exp(-gamma |x - z|^2), LIBSVM's C-SVC, one-vs-one (gamma 0 means
    1 / n_features). decision_function gives the votes per class, or for two classes the raw
    value, as scikit-learn's SVC does."""

    _cpp_name = "RbfSvm"

    def __init__(
        self,
        *,
        C: float = 1.0,
        gamma: float = 0.0,
        eps: float = 1e-3,
        cache_mb: float = 100.0,
        max_iterations: int = 0,
    ) -> None:
        self.C = C
        self.gamma = gamma
        self.eps = eps
        self.cache_mb = cache_mb
        self.max_iterations = max_iterations

    def decision_function(self, X: npt.ArrayLike) -> _Array:
        """Votes per class (n_samples, n_classes) in classes_ order; for two classes the raw
        value (n_samples,), positive for classes_[1]."""
        model = self._fitted()
        x = _features(X, "RbfSvm", self.n_features_in_)
        if len(self.classes_) == 2:
            raw = np.asarray(model.pair_decision_function(x))[:, 0]
            # The pair's value is positive for the compiled model's first class.
            return typing.cast(_Array, raw if self._order[0] == 1 else -raw)
        return typing.cast(_Array, np.asarray(model.decision_function(x))[:, self._order])

    @property
    def support_vectors_(self) -> _Array:
        """(n_support, n_features) support vectors, in training order."""
        return typing.cast(_Array, self._fitted().support_vectors_)


class Mlp(_Probabilistic):
    """Multi-layer perceptron, one or two hidden layers (`hidden` widths), softmax output;
    predict_proba gives the class probabilities. Scale the features first."""

    _cpp_name = "Mlp"

    def __init__(
        self,
        *,
        hidden: typing.Sequence[int] = (32,),
        activation: str = "tanh",
        optimizer: str = "adam",
        learning_rate: float = 1e-2,
        momentum: float = 0.9,
        l2: float = 1e-4,
        epochs: int = 200,
        batch_size: int = 32,
        tolerance: float = 1e-5,
        patience: int = 10,
        seed: int = 1,
    ) -> None:
        self.hidden = hidden
        self.activation = activation
        self.optimizer = optimizer
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.l2 = l2
        self.epochs = epochs
        self.batch_size = batch_size
        self.tolerance = tolerance
        self.patience = patience
        self.seed = seed

    def _cpp_params(self, code: typing.Callable[[typing.Any], int]) -> dict[str, typing.Any]:
        p = self.get_params()
        p["hidden"] = list(p["hidden"])
        return p


def _keyword_hints(cls: typing.Any) -> None:
    """A misspelled parameter names itself and the closest valid one."""
    init = cls.__init__

    @functools.wraps(init)
    def __init__(self: typing.Any, *args: typing.Any, **kwargs: typing.Any) -> None:
        valid = cls._param_names()
        for k in kwargs:
            if k not in valid:
                close = difflib.get_close_matches(k, valid, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise TypeError(
                    f"{cls.__name__}() got an unexpected keyword argument {k!r}{hint} "
                    f"(its parameters: {', '.join(valid)})"
                )
        init(self, *args, **kwargs)

    cls.__init__ = __init__


for _cls in (LinearSvm, Knn, Lda, RbfSvm, Mlp):
    _keyword_hints(_cls)

_Estimator = typing.Union[LinearSvm, Knn, Lda, RbfSvm, Mlp]


def _prototype(model: typing.Any) -> typing.Any:
    """The unfitted compiled model an evaluation function trains copies of."""
    if isinstance(model, _Classifier):
        return model._make_model()
    raise TypeError(
        "expected a taxel.learn classifier (LinearSvm, Knn, Lda, RbfSvm, Mlp), got "
        f"{type(model).__module__}.{type(model).__qualname__}"
    )


def cross_validate(
    model: _Estimator,
    X: npt.ArrayLike,
    y: npt.ArrayLike,
    groups: npt.ArrayLike | None = None,
    *,
    folds: int = 5,
    seed: int = 1,
    grouped: bool = False,
    snr_db: float = float("inf"),
    noise_target: str = "test_only",
    threads: int = 0,
) -> CvReport:
    """Stratified k-fold cross-validation of a classifier's parameters (integer labels); grouped
    keeps each group in one fold; snr_db adds white noise to the test (or both) features. The
    folds train on `threads` threads (0: every core); the report does not depend on it. Returns
    a CvReport."""
    return typing.cast(CvReport, _cpp.cross_validate(
        _prototype(model), X, y, groups, folds=folds, seed=seed, grouped=grouped,
        snr_db=snr_db, noise_target=noise_target, threads=threads,
    ))


def five_by_two_cv(
    a: _Estimator,
    b: _Estimator,
    X: npt.ArrayLike,
    y: npt.ArrayLike,
    groups: npt.ArrayLike | None = None,
    *,
    alpha: float = 0.05,
    seed: int = 1,
    grouped: bool = False,
    snr_db: float = float("inf"),
    noise_target: str = "test_only",
    threads: int = 0,
) -> FiveByTwoResult:
    """Dietterich's 5x2cv paired t test of two classifiers' parameters on the same splits
    (integer labels); the ten rounds run on `threads` threads (0: every core). Returns a
    FiveByTwoResult."""
    return typing.cast(FiveByTwoResult, _cpp.five_by_two_cv(
        _prototype(a), _prototype(b), X, y, groups, alpha=alpha, seed=seed, grouped=grouped,
        snr_db=snr_db, noise_target=noise_target, threads=threads,
    ))
