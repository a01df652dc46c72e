"""Imitation datasets: ``.npz`` round trips, incremental and throttled writes, splits."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _imitation import fake_episode

from semexplore_gym.training.dataset import DatasetWriter, ImitationDataset

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_dataset_round_trip_and_incremental_writes(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    path = tmp_path / "d.npz"
    writer = DatasetWriter(path, meta={"expert": "x"})
    ep0, ep1 = fake_episode(5, 0, rng), fake_episode(3, 0, rng)
    writer.add(ep0)
    # The file is complete after the first episode already (nothing lost on interruption).
    first = ImitationDataset.load(path)
    assert len(first) == 5 and first.meta == {"expert": "x"}
    writer.add(ep1)
    back = ImitationDataset.load(path)
    assert len(back) == 8 and back.n_episodes == 2
    np.testing.assert_array_equal(back.episode_ids, [0] * 5 + [1] * 3)  # second episode id shifted
    np.testing.assert_array_equal(
        back.obs["image"], np.concatenate([ep0.obs["image"], ep1.obs["image"]])
    )
    np.testing.assert_array_equal(
        back.obs["scan"], np.concatenate([ep0.obs["scan"], ep1.obs["scan"]])
    )
    np.testing.assert_array_equal(back.actions, np.concatenate([ep0.actions, ep1.actions]))
    assert not list(tmp_path.glob("*.tmp"))
    # append=True continues an existing file.
    DatasetWriter(path, append=True).add(fake_episode(2, 7, rng))
    assert ImitationDataset.load(path).episode_ids.tolist() == [0] * 5 + [1] * 3 + [2] * 2


def test_split_by_episode_holds_out_whole_episodes() -> None:
    rng = np.random.default_rng(1)
    data = ImitationDataset.empty()
    for e in range(4):
        data = data.concatenate(fake_episode(3 + e, 0, rng))
    train, held = data.split_by_episode(0.25, np.random.default_rng(0))
    assert len(train) + len(held) == len(data) and held.n_episodes == 1 and train.n_episodes == 3
    assert not set(train.episode_ids) & set(held.episode_ids)


def test_dataset_errors() -> None:
    with pytest.raises(ValueError, match="samples"):
        ImitationDataset(
            {"scan": np.zeros((3, 2))}, np.zeros((2, 2), np.float32), np.zeros(2, np.int64)
        )
    with pytest.raises(FileNotFoundError, match="dataset not found"):
        ImitationDataset.load("/nonexistent/d.npz")


def test_concatenate_all_matches_chained_concatenate() -> None:
    rng = np.random.default_rng(2)
    parts = [fake_episode(n, e, rng) for n, e in [(3, 4), (2, 0), (4, 9)]]
    parts[0].meta["a"] = 1
    chained = parts[0].concatenate(parts[1]).concatenate(parts[2])
    once = ImitationDataset.concatenate_all([ImitationDataset.empty({"w": 2}), *parts])
    np.testing.assert_array_equal(once.episode_ids, chained.episode_ids)
    np.testing.assert_array_equal(once.actions, chained.actions)
    np.testing.assert_array_equal(once.obs["image"], chained.obs["image"])
    assert once.meta == {"w": 2, "a": 1}


def test_dataset_writer_throttles_rewrites_and_flushes(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    path = tmp_path / "d.npz"
    writer = DatasetWriter(path, meta={"k": 1}, min_interval_s=3600.0)
    writer.add(fake_episode(4, 0, rng))  # the first episode is written at once
    writer.add(fake_episode(2, 0, rng))  # within the interval: kept in memory only
    assert len(ImitationDataset.load(path)) == 4 and len(writer.data) == 6
    writer.flush()
    back = ImitationDataset.load(path)
    assert len(back) == 6 and back.episode_ids.tolist() == [0] * 4 + [1] * 2
    assert back.meta == {"k": 1}
