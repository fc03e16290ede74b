"""The evaluation's results as dataclasses: a scene and its settings, a time's spread, a mode's
quality row, the equal-time and equal-error comparisons, a mode's timing summary, a goal's
verdict. Where results.json holds a result, the field names and order are its keys
(dataclasses.asdict gives its dicts)."""

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Optional

from ..benchlib import median

MODES = ("reuse", "retrace", "pathtrace")
REF_SEED = 9001          # references never share a seed with a measured run


@dataclass
class Scene:
    key: str
    path: Path
    camera: str                  # "still" or "moving"
    frames: list                 # the quality frames
    ref_spp: int
    timing_frames: tuple         # (first, last) of the timing runs
    sweep: list                  # spp of the sweep
    triangles: Optional[str] = None


@dataclass
class Stats:
    """Median, min and max of measured values."""
    median: float
    min: float
    max: float

    @classmethod
    def of(cls, values):
        return cls(median(values), min(values), max(values))

    def fmt(self, f="{:.3f}"):
        return f"{f.format(self.median)} [{f.format(self.min)}-{f.format(self.max)}]"


@dataclass
class QualityRow:
    """One (mode, spp, fixed noise) over its runs: time, relMSE and flicker."""
    mode: str
    spp: int
    fixed_noise: bool
    time_s_per_frame: Stats
    relmse: float
    relmse_runs: list
    relmse_trim: float
    relmse_trim_runs: list
    relmse_median_frame: float
    flicker: float
    flicker_runs: list
    relmse_per_frame: list
    flicker_per_pair: list


@dataclass
class EqualTimeRound:
    pathtrace_spp: int
    reuse_s: Stats
    pathtrace_s: Stats
    ratio: float                 # pathtrace / reuse, medians
    ratios_per_seed: list


@dataclass
class EqualTime:
    reuse_spp: int
    pathtrace_spp: int
    rounds: list                 # EqualTimeRound
    time_ratio_pathtrace_over_reuse: float
    within_5_percent: bool
    reuse: QualityRow
    pathtrace_fresh: QualityRow
    pathtrace_fixed: QualityRow


@dataclass
class ErrorPoint:
    spp: int
    time_s: float
    relmse: float


@dataclass
class TimeToTarget:
    """When one mode reaches the equal-error target."""
    time_s: Optional[float]
    how: str
    tail_slope: float
    points: list                 # ErrorPoint


@dataclass
class TrimmedEqualError:
    target_relmse_trim: float
    reuse: Optional[float]
    pathtrace: Optional[float]
    speedup: Optional[float]


@dataclass
class EqualError:
    target_relmse: float
    target_from: str
    reuse: TimeToTarget
    pathtrace: TimeToTarget
    speedup: Optional[float]
    speedup_lower_bound: bool
    trimmed: TrimmedEqualError


@dataclass
class TimingSummary:
    """One mode's timing runs over the longer frame range."""
    wall_s_per_frame: Stats
    kernel_s_per_frame: Stats
    total_s: Stats
    frame0_s: float
    process_s: Stats
    per_run_wall: list
    stage_share_percent: dict
    stage_s_per_frame: dict
    rays_per_frame: dict
    slots_reused_fraction: Optional[float]
    per_frame_wall: list = field(repr=False)  # per run, per frame; plotted, not in results.json

    def to_json(self):
        d = asdict(self)
        del d["per_frame_wall"]
        return d


@dataclass
class SceneResult:
    scene: Scene
    refs: list                   # reference images of the quality frames
    ref_key: str
    settings: dict               # (mode, spp, fixed) -> metrics.SettingRuns
    identical: list              # reuse vs retrace per seed: largest |difference|
    equal_time: EqualTime
    equal_error: EqualError
    timing: dict                 # mode -> TimingSummary

    def setting(self, mode, spp, fixed=False):
        return self.settings[(mode, spp, fixed)]

    def sorted_settings(self):
        return sorted(self.settings.values(), key=lambda s: (s.mode, s.fixed, s.spp))

    def time_ratio(self):
        """reuse / retrace wall seconds per frame."""
        return (self.timing["reuse"].wall_s_per_frame.median
                / self.timing["retrace"].wall_s_per_frame.median)


@dataclass
class Goal:
    goal: str
    scene: str
    measured: str
    met: Optional[bool]          # None: undetermined

    @property
    def verdict(self):
        return "undetermined" if self.met is None else ("met" if self.met else "not met")

    def to_json(self):
        return {"goal": self.goal, "scene": self.scene, "measured": self.measured,
                "met": self.met is True, "verdict": self.verdict}
