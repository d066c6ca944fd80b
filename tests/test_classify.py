"""kNN degeneracies (physics.md 6.7), wrapper selection hygiene, any scikit-learn estimator."""

from __future__ import annotations

import warnings
from typing import Any, ClassVar

import numpy as np
import pytest
from mdf_knn import Knn
from mdf_sklearn import SklearnClassifier

from mdframework import ConfigError
from mdframework.classify import (
    Standardizer,
    balanced_accuracy,
    confusion_matrix,
    fit_predict,
    optimistic_select,
    wrapper_select,
)
from mdframework.interfaces import Classifier
from mdframework.plugins import default_registry, is_plugin_bug


def knn(k: int = 5, tie_rule: str = "nearest") -> Knn:
    return Knn(Knn.Config(k=k, tie_rule=tie_rule))  # type: ignore[arg-type]


def test_zero_variance_feature_is_guarded() -> None:
    x = np.array([[1.0, 0.3], [2.0, 0.3], [3.0, 0.3], [10.0, 0.3]])
    s = Standardizer.fit(x)
    z = s.transform(x)
    assert np.all(np.isfinite(z)) and np.allclose(z[:, 1], 0.0)
    y = np.array(["a", "a", "b", "b"])
    pred = knn(k=1).fit(x, y).predict(np.array([[9.0, 0.3], [1.2, 0.31]]))
    assert list(pred) == ["b", "a"]


def test_standardisation_uses_training_statistics_only() -> None:
    train = np.array([[0.0], [2.0]])
    s = Standardizer.fit(train)
    assert s.transform(np.array([[1000.0]]))[0, 0] == pytest.approx(999.0)


def test_vote_tie_goes_to_the_nearest_member() -> None:
    # k = 4 with a 2-2 split: class "z" has the single nearest neighbour
    x = np.array([[0.0], [1.0], [-1.5], [2.0], [5.0]])
    y = np.array(["z", "a", "a", "z", "a"])
    q = np.array([[0.1]])
    assert knn(k=4).fit(x, y).predict(q)[0] == "z"
    assert knn(k=4, tie_rule="lowest").fit(x, y).predict(q)[0] == "a"
    # symmetric swap of labels: the rule follows the nearest member, not the label name
    assert knn(k=4).fit(x, np.array(["a", "z", "z", "a", "z"])).predict(q)[0] == "a"


def test_five_classes_two_two_one_split() -> None:
    x = np.array([[1.0], [-1.2], [2.0], [-2.2], [3.0]])
    y = np.array(["walk", "run", "walk", "run", "box"])
    assert knn(k=5).fit(x, y).predict(np.array([[0.0]]))[0] == "walk"


def test_more_neighbours_than_training_records_is_refused() -> None:
    """k above the training set would let every record vote (the largest class always wins):
    refused naming classifier.k, where it used to be lowered silently; k equal to it is a
    legal, if degenerate, vote."""
    x = np.array([[1.0], [-1.2], [2.0], [-2.2], [3.0]])
    y = np.array(["walk", "run", "walk", "run", "box"])
    with pytest.raises(ConfigError, match=r"classifier\.k: 6 neighbours, but .* only 5"):
        knn(k=6).fit(x, y)
    assert knn(k=5).fit(x, y).neighbours(np.array([[0.0]]))[1].shape == (1, 5)


def test_distance_ties_follow_training_order() -> None:
    """Four training points at the same distance, k = 1: the earliest one wins, and the
    decision is the same on every call (no dependence on the search algorithm's order)."""
    x = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    q = np.zeros((1, 2))
    for labels in (["a", "b", "c", "d"], ["d", "c", "b", "a"]):
        model = knn(k=1).fit(x, np.array(labels))
        assert model.predict(q)[0] == labels[0]
        _, idx = model.neighbours(q)
        assert list(idx[0]) == [0]
    # k = 3 of 4 equidistant: the first three in training order vote
    model = knn(k=3).fit(x, np.array(["a", "b", "b", "a"]))
    assert model.predict(q)[0] == "b"


def test_unequal_class_sizes_reported_per_class() -> None:
    y_true = np.array(["walk"] * 93 + ["run"] * 32 + ["leap"] * 140)
    y_pred = y_true.copy()
    y_pred[:19] = "run"  # 74/93 walk correct
    y_pred[93:95] = "walk"  # 30/32 run correct
    cm = confusion_matrix(y_true, y_pred, ["walk", "run", "leap"])
    assert np.allclose(cm.sum(axis=1), 1.0)
    assert cm[0, 0] == pytest.approx(74 / 93) and cm[1, 1] == pytest.approx(30 / 32)
    assert balanced_accuracy(y_true, y_pred) == pytest.approx((74 / 93 + 30 / 32 + 1) / 3)


class Spy(Classifier):
    """A 1-NN classifier that records every row it is shown."""

    name = "spy"
    Config = Knn.Config
    seen: ClassVar[list[np.ndarray]] = []

    def __init__(self) -> None:
        self.inner = knn(k=1)

    def fit(self, features: Any, labels: Any) -> Spy:
        Spy.seen.append(np.asarray(features))
        self.inner.fit(features, labels)
        return self

    def predict(self, features: Any) -> Any:
        Spy.seen.append(np.asarray(features))
        return self.inner.predict(features)


def test_wrapper_selection_never_sees_the_test_split(rng: np.random.Generator) -> None:
    n = 60
    y = np.repeat(["a", "b", "c"], n // 3)
    x = rng.normal(size=(n, 7))
    x[:, 2] += np.repeat([0.0, 3.0, 6.0], n // 3)  # feature 2 separates the classes
    test = rng.permutation(n)[:24]
    train = np.setdiff1d(np.arange(n), test)
    x_test = x[test] + 1000.0  # mark the test rows: any of them seen would be found
    Spy.seen = []
    sel = wrapper_select(x[train], y[train], Spy, sizes=(1, 2), folds=4)
    seen = np.concatenate([a.ravel() for a in Spy.seen])
    assert np.all(np.abs(seen) < 500.0), "wrapper selection saw test data"
    assert 2 in sel.subset and sel.score > 0.9
    assert len(sel.scores) == 7 + 21
    # the optimistic variant does look at the test data (and says so in its name)
    Spy.seen = []
    optimistic_select(x[train], y[train], x_test, y[test], Spy, sizes=(1,))
    assert np.any(np.abs(np.concatenate([a.ravel() for a in Spy.seen])) > 500.0)


def test_grouped_wrapper_folds_never_split_a_group(rng: np.random.Generator) -> None:
    """With ``groups`` (e.g. subjects), no inner fold trains and tests on one group's records,
    and a fold scores only the classes it trains on; without them, folds split records."""
    n = 60
    y = np.repeat(["a", "b", "c"], n // 3)
    groups = np.tile(np.repeat(np.arange(5), 4), 3)  # 5 subjects, 4 records of each class
    x = rng.normal(size=(n, 7))
    x[:, 0] = groups  # feature 0 names each record's group: what a fold saw is readable
    x[:, 2] += np.repeat([0.0, 30.0, 60.0], n // 3)

    def pairs() -> list[tuple[set[float], set[float]]]:
        seen = Spy.seen
        return [(set(seen[i][:, 0]), set(seen[i + 1][:, 0])) for i in range(0, len(seen), 2)]

    Spy.seen = []
    sel = wrapper_select(x, y, Spy, sizes=(1,), folds=4, groups=groups)
    assert all(not (fit & test) for fit, test in pairs())
    assert len(Spy.seen) == 2 * 4 * 7 and 2 in sel.subset
    Spy.seen = []
    wrapper_select(x, y, Spy, sizes=(1,), folds=4)
    assert any(fit & test for fit, test in pairs())  # record folds do split groups
    with pytest.raises(ValueError, match="two groups"):
        wrapper_select(x, y, Spy, sizes=(1,), groups=np.zeros(n))


def test_grouped_wrapper_says_nothing_of_a_class_in_fewer_groups_than_folds(
    rng: np.random.Generator,
) -> None:
    """A class of fewer records than folds (two records of two subjects, five folds) is simply
    in fewer folds: scikit-learn's 'least populated class ... less than n_splits=5' warning,
    which names none of the user's fields, does not reach them."""
    y = np.array(["a"] * 20 + ["b"] * 20 + ["c"] * 2)
    groups = np.concatenate([np.arange(40) % 5, [0, 1]])
    x = rng.normal(size=(42, 3))
    x[:, 0] += (y == "b") * 5.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sel = wrapper_select(x, y, lambda: Knn(Knn.Config(k=1)), sizes=(1,), groups=groups)
    assert sel.subset == (0,)


def test_any_sklearn_estimator_through_the_plugin(rng: np.random.Generator) -> None:
    reg = default_registry()
    assert reg.get("classifier", "sklearn") is SklearnClassifier
    x = np.concatenate([rng.normal(0, 1, (30, 3)), rng.normal(4, 1, (30, 3))])
    y = np.repeat(["a", "b"], 30)
    for path, params in (
        ("sklearn.svm.SVC", {"C": 10.0}),
        ("sklearn.ensemble.RandomForestClassifier", {"n_estimators": 20, "random_state": 0}),
    ):
        cfg = SklearnClassifier.Config(estimator=path, params=params)  # type: ignore[call-arg]
        model = SklearnClassifier(cfg).fit(x, y)
        assert np.mean(model.predict(x) == y) > 0.95


def test_bad_estimator_path_is_a_validation_error() -> None:
    from pydantic import ValidationError

    with pytest.raises(ValidationError, match=r"cannot import 'sklearn\.svm\.NoSuchThing'"):
        SklearnClassifier.Config(estimator="sklearn.svm.NoSuchThing")  # type: ignore[call-arg]
    with pytest.raises(ValidationError, match="not a classifier"):
        SklearnClassifier.Config.model_validate(
            {"estimator": "numpy.linalg.norm"}, context={"allow_import": True}
        )


def test_estimators_outside_sklearns_classifiers_need_allow_import() -> None:
    """A config cannot import (and so run) arbitrary modules: only scikit-learn's classifiers
    are accepted unless the command line passes --allow-import."""
    import sys

    from pydantic import ValidationError

    for path in ("numpy.linalg.norm", "os.system", "mdf_knn.knn.KnnClassifier"):
        with pytest.raises(ValidationError, match="--allow-import"):
            SklearnClassifier.Config(estimator=path)  # type: ignore[call-arg]
    # a path outside sklearn is refused before anything is imported
    sys.modules.pop("this", None)
    with pytest.raises(ValidationError, match="--allow-import"):
        SklearnClassifier.Config(estimator="this.Zen")  # type: ignore[call-arg]
    assert "this" not in sys.modules
    # sklearn estimators that are not classifiers, and private paths, are refused too
    for path in ("sklearn.linear_model.LinearRegression", "sklearn.svm._classes.SVC"):
        with pytest.raises(ValidationError, match=r"--allow-import|not one of"):
            SklearnClassifier.Config(estimator=path)  # type: ignore[call-arg]
    # with the flag, any class with fit/predict is accepted
    cfg = SklearnClassifier.Config.model_validate(
        {"estimator": "sklearn.linear_model.LinearRegression"}, context={"allow_import": True}
    )
    assert cfg.estimator.endswith("LinearRegression")


class Failing(Spy):
    """A classifier plugin whose predict fails (a third party's bug)."""

    name = "failing"

    def predict(self, features: Any) -> Any:
        raise KeyError("oops")


def test_a_classifier_that_fails_is_named_in_the_error(rng: np.random.Generator) -> None:
    """The exception of a classifier plugin's method carries a note naming the plugin and its
    contract check, which the CLI's internal error shows (it named nobody)."""
    x, y = rng.normal(size=(20, 3)), np.repeat(["a", "b"], 10)
    with pytest.raises(KeyError) as caught:
        wrapper_select(x, y, Failing, sizes=(1,), folds=2)
    assert getattr(caught.value, "__notes__", []) == [
        "in predict() of the classifier plugin 'failing' (test_classify.Failing); check it with "
        "mdframework.testing.check_classifier"
    ]


#: what a broken classifier plugin's predict returns for labels ``y`` (test rows), and the
#: message that names its bug
WRONG_PREDICTIONS = {
    "one short": (lambda y: y[:-1], "predict() returned labels of shape (9,), not (10,)"),
    "a column": (lambda y: y[:, None], "predict() returned labels of shape (10, 1), not (10,)"),
    "None": (lambda y: None, "predict() returned None, not 10 labels"),
    "numbers": (
        lambda y: np.zeros(len(y), dtype=int),
        "predict() returned labels it was not trained on: 0 (trained on: 'a', 'b')",
    ),
    "a new label": (
        lambda y: np.where(y == "a", "a", "c"),
        "predict() returned labels it was not trained on: 'c' (trained on: 'a', 'b')",
    ),
}


@pytest.mark.parametrize("how", sorted(WRONG_PREDICTIONS))
@pytest.mark.parametrize("selection", ["none", "wrapper"])
def test_a_classifier_that_predicts_the_wrong_thing_is_named(
    how: str, selection: str, rng: np.random.Generator
) -> None:
    """A classifier plugin whose predict() gives other than one training label per row is its
    bug, named as such: a label it never saw (integer class codes) was scored as a miss, a
    balanced accuracy of 0 without a word, and a wrong shape failed in mdframework's own code
    (or differently with and without the wrapper), naming nobody."""
    wrong, why = WRONG_PREDICTIONS[how]

    class Wrong(Spy):
        """Predicts the wrong thing."""

        name = "wrong"

        def predict(self, features: Any) -> Any:
            return wrong(super().predict(features))

    x, y = rng.normal(size=(20, 3)), np.repeat(["a", "b"], 10)
    with pytest.raises((TypeError, ValueError)) as caught:
        if selection == "none":
            fit_predict(Wrong(), x[::2], y[::2], x[1::2])
        else:
            wrapper_select(x, y, Wrong, sizes=(1,), folds=2)
    text = str(caught.value)
    if selection == "wrapper":  # the folds are smaller
        text = text.replace("(5,", "(10,").replace("(4,", "(9,").replace(" 5 ", " 10 ")
    assert text.startswith(why), caught.value
    assert is_plugin_bug(caught.value)
    assert caught.value.__notes__[0].startswith("in predict() of the classifier plugin 'wrong'")


def test_a_classifier_whose_fit_returns_none_is_named(rng: np.random.Generator) -> None:
    """fit() must return the classifier: one that returns None was reported as an
    AttributeError in predict()."""

    class NoSelf(Spy):
        """Forgets to return itself."""

        name = "no_self"

        def fit(self, features: Any, labels: Any) -> Any:
            super().fit(features, labels)
            return None

    x, y = rng.normal(size=(20, 3)), np.repeat(["a", "b"], 10)
    with pytest.raises(TypeError, match=r"^fit\(\) returned NoneType, not the classifier") as c:
        fit_predict(NoSelf(), x, y, x)
    assert c.value.__notes__[0].startswith("in fit() of the classifier plugin 'no_self'")


def test_predicted_labels_in_a_list_are_an_array(rng: np.random.Generator) -> None:
    """A predict() that returns its labels as a list works with and without the wrapper (the
    wrapper failed on it with an unnamed TypeError)."""

    class AsList(Spy):
        """Predicts a list."""

        name = "as_list"

        def predict(self, features: Any) -> Any:
            return list(super().predict(features))

    x, y = rng.normal(size=(20, 3)), np.repeat(["a", "b"], 10)
    x[:, 0] += (y == "b") * 20.0
    assert np.array_equal(fit_predict(AsList(), x, y, x), y)
    assert wrapper_select(x, y, AsList, sizes=(1,), folds=2).subset == (0,)


def test_a_large_constant_feature_is_only_centred() -> None:
    """A feature constant at 7,770,000.3 (numpy's std of it is 9e-10, rounding, not spread):
    treated as zero-variance, so a query 1 mm/s off it is 0.001 off in z, not 1e6."""
    x = np.stack([np.arange(7.0), np.full(7, 7770000.3)], axis=1)
    assert x[:, 1].std() > 1e-12  # the rounding the relative tolerance is there for
    s = Standardizer.fit(x)
    assert s.scale[1] == 1.0
    z = s.transform(np.array([[3.0, 7770000.301]]))
    assert z[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert z[0, 1] == pytest.approx(0.001, abs=1e-6)


def test_wrapper_prefers_fewer_features_at_equal_score(rng: np.random.Generator) -> None:
    """Feature 0 alone separates the classes perfectly, and so does any pair holding it: at the
    same score the smaller subset wins, (0,) rather than (0, 1)."""
    y = np.repeat(["a", "b"], 20)
    x = rng.normal(size=(40, 3))
    x[:, 0] += (y == "b") * 20.0
    sel = wrapper_select(x, y, lambda: knn(k=1), sizes=(1, 2), folds=4)
    assert sel.scores[(0,)] == sel.scores[(0, 1)] == 1.0
    assert sel.subset == (0,)


def test_grouped_wrapper_does_not_score_a_class_it_never_trained_on(
    rng: np.random.Generator,
) -> None:
    """Class 'c' is recorded by subject 0 only: the fold holding subject 0 out cannot know 'c'
    and leaves its records out of that fold's score, so perfectly separable classes score 1.0
    (counted as wrong they would pull the score below 1)."""
    y = np.array(["a"] * 20 + ["b"] * 20 + ["c"] * 4)
    groups = np.concatenate([np.arange(40) % 4, [0, 0, 0, 0]])
    x = rng.normal(size=(44, 2))
    x[:, 0] += np.select([y == "b", y == "c"], [20.0, 40.0], 0.0)
    sel = wrapper_select(x, y, lambda: knn(k=1), sizes=(1,), folds=4, groups=groups)
    assert sel.subset == (0,) and sel.score == 1.0


def test_a_knn_metric_that_cannot_be_computed_is_a_config_error() -> None:
    """A misspelt metric, or one that needs parameters the plugin does not take (seuclidean's
    variances, mahalanobis' covariance), used to pass validation and fail at the first
    prediction as an internal error of the plugin; it is refused naming classifier.metric. A
    metric it takes gives the distances it names."""
    from mdframework.experiment import classifier_factory

    for metric in ("euclidian", "seuclidean", "mahalanobis", "precomputed"):
        with pytest.raises(ConfigError, match=rf"classifier\.metric: '{metric}' is not one of"):
            classifier_factory({"kind": "knn", "metric": metric}, "e.toml")
    make = classifier_factory({"kind": "knn", "k": 1, "metric": "manhattan"}, "e.toml")
    x = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]])  # std (0.816, 0.471)
    dist, idx = make().fit(x, np.array(["a", "b", "c"])).neighbours(np.array([[1.0, 0.0]]))
    assert idx[0, 0] == 0 and dist[0, 0] == pytest.approx(1 / np.sqrt(2 / 3), rel=1e-12)


def test_a_knn_metric_of_boolean_data_is_a_config_error() -> None:
    """scikit-learn's metrics of boolean data (jaccard, dice, yule...) turn the standardised
    features into booleans (every nonzero z-score True): every distance came out 0 and every
    query got the first training records' class, with nothing but a DataConversionWarning. They
    are refused naming classifier.metric."""
    from mdframework.experiment import classifier_factory

    for metric in ("jaccard", "dice", "yule", "russellrao"):
        with pytest.raises(ConfigError, match=rf"classifier\.metric: '{metric}' is not one of"):
            classifier_factory({"kind": "knn", "metric": metric}, "e.toml")
