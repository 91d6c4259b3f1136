# Type stub of the gyrodrift package (python/gyrodrift/__init__.py; docs/python.md).
from os import PathLike
from typing import Any, Callable, Literal, Sequence

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]

class UsageError(ValueError): ...
class DataError(ValueError): ...
class FileError(OSError): ...

def decompose(
    x: ArrayLike, *,
    method: Literal["emd", "eemd", "ceemdan", "iceemdan", "beemdan"] = ...,
    stop: Literal["rilling", "snumber", "fixed", "sd"] = ...,
    ensemble: int = ..., noise: float = ..., seed: int = ..., threads: int = ...,
    max_imfs: int = ..., max_sifts: int = ..., s_number: int = ..., fixed_sifts: int = ...,
    sd: float = ..., noise_scaling: Literal["colominas2014", "constant-snr"] = ...,
    bound: Literal["ensemble", "energy", "stages", "full"] = ..., band: float = ..., noise_stages: int = ...,
    noise_realisations: ArrayLike | None = ...,
    progress: Callable[[float], object] | None = ...,
) -> tuple[Array, Array, dict[str, Any]]: ...

def allan(
    x: ArrayLike, *, rate_hz: float,
    type: Literal["rate", "angle"] = ...,
    dev: Literal["adev", "oadev", "mdev", "hdev", "ohdev", "tdev", "totdev"] = ...,
    taus: Literal["all", "octave", "decade"] | Sequence[float] = ...,
    units: Literal["dph", "dps", "rads"] = ..., confidence: float = ..., threads: int = ...,
    fit_tau_min: float = ..., fit_tau_max: float = ...,
    logged: Sequence[bool] | None = ..., record_starts: Sequence[int] = ...,
) -> dict[str, Any]: ...

def noise_terms(
    tau_s: ArrayLike, adev_dph: ArrayLike, edf: ArrayLike, *, fit_tau_min: float = ...,
    fit_tau_max: float = ..., min_share: float = ..., significance: float = ...,
    sample_period_s: float = ...,
) -> dict[str, Any]: ...

def simulate(
    *, duration: float | None = ...,
    profile: str | PathLike[str] | tuple[ArrayLike, ArrayLike] = ...,
    preset: Literal["navigation", "tactical"] = ..., rate_hz: float = ..., seed: int = ...,
    winding: str = ..., asymmetry: float | None = ..., input_rate_dph: float = ...,
    noise: bool = ...,
) -> dict[str, Any]: ...

def read_log(
    path: str | PathLike[str], *, gaps: Literal["error", "interpolate", "split", "carry"] = ...,
    rate_hz: float | None = ..., delimiter: Literal["auto", "comma", "tab", "semicolon"] = ...,
    names: str | Sequence[str] = ..., skip_rows: int = ...,
    bad_lines: Literal["error", "skip"] = ..., ulog_topic: str = ..., ulog_instance: int = ...,
    ulog_units: Literal["dph", "dps", "rads"] = ...,
) -> dict[str, Any]: ...

def read_ulog(
    path: str | PathLike[str], *, decode: str | Sequence[str] = ...
) -> dict[str, Any]: ...

def ulog_columns(
    path: str | PathLike[str], *, topic: str = ..., instance: int = ..., axes: Sequence[str] = ...,
    temperature_field: str = ..., units: Literal["dph", "dps", "rads"] = ...,
) -> dict[str, Any]: ...

def plan(
    *, hours: float = ..., min_c: float = ..., max_c: float = ..., rate: float = ...,
    dwell_min: float = ...,
) -> dict[str, Any]: ...

class DriftModel:
    def __init__(self) -> None: ...
    # **settings: the fit settings, fit_defaults()'s keys (named and defaulted by the library).
    def fit(
        self, y: ArrayLike, temperature: ArrayLike | None = ..., *,
        mode: Literal["compensate", "predict"] = ..., target: str = ...,
        temperature_columns: Sequence[str] | None = ..., source: str = ...,
        units: Literal["dph", "dps", "rads"] = ...,
        record_starts: Sequence[int] = ...,
        logged: Sequence[bool] | None = ...,
        progress: Callable[[float], object] | None = ...,
        **settings: Any,
    ) -> DriftModel: ...
    def estimate(
        self, temperature: ArrayLike, *, record_starts: Sequence[int] = ...,
        rate_hz: float | None = ...,
    ) -> tuple[Array, Array]: ...
    def compensate(
        self, y: ArrayLike, temperature: ArrayLike, *, record_starts: Sequence[int] = ...,
        rate_hz: float | None = ...,
    ) -> Array: ...
    def compensation_summary(
        self,
        y: ArrayLike,
        temperature: ArrayLike,
        *,
        record_starts: Sequence[int] = ...,
        drift_window_s: float = ...,
        logged: Sequence[bool] | None = ...,
        truth: ArrayLike | None = ...,
        rate_hz: float | None = ...,
    ) -> dict[str, Any]: ...
    def coefficients(
        self, *, reference_temperature: float | None = ...
    ) -> list[dict[str, Any]]: ...
    def predict(
        self, y: ArrayLike, temperature: ArrayLike | None = ..., *, horizon: int = ...,
        protocol: Literal["causal", "paper"] = ..., window: int = ..., mirror: float = ...,
        windows: int = ..., causal_ensemble: int = ..., threads: int = ...,
        progress: Callable[[float], object] | None = ..., rate_hz: float | None = ...,
    ) -> tuple[int, Array]: ...
    def save(self, path: str | PathLike[str]) -> None: ...
    @classmethod
    def load(cls, path: str | PathLike[str], axis: str | None = ...) -> DriftModel: ...
    @classmethod
    def load_axes(cls, path: str | PathLike[str]) -> list[DriftModel]: ...
    @staticmethod
    def save_axes(path: str | PathLike[str], models: Sequence[DriftModel]) -> None: ...
    @property
    def summary(self) -> str: ...
    @property
    def sub_models(self) -> list[dict[str, Any]]: ...
    @property
    def mode(self) -> str: ...
    @property
    def method(self) -> str: ...
    @property
    def target(self) -> str: ...
    @property
    def temperature_columns(self) -> list[str]: ...
    @property
    def temperature_range_c(self) -> tuple[float, float]: ...
    @property
    def fitted(self) -> bool: ...
    @property
    def rate_hz(self) -> float: ...

def export(
    models: str | PathLike[str] | DriftModel | Sequence[str | PathLike[str]] | Sequence[DriftModel],
    *,
    format: Literal["c", "json-coefficients", "px4"] = ..., single_precision: bool = ...,
    prefix: str = ..., device_ids: Sequence[int] = ...,
) -> str: ...

def temperature_warning(temperature: ArrayLike, name: str = ...) -> str: ...

def select_modes(
    x: ArrayLike, imfs: ArrayLike, residue: ArrayLike, *,
    criterion: Literal["pdf", "komaty", "energy"] = ...,
    distance: Literal["l2", "l1", "hellinger", "jensen-shannon", "bhattacharyya"] = ...,
    realisations: int = ..., confidence: float = ..., seed: int = ..., band: float = ...,
    threads: int = ...,
) -> dict[str, Any]: ...

def evaluate(
    y: ArrayLike, temperature: ArrayLike | None = ..., truth: ArrayLike | None = ..., *,
    mode: Literal["predict", "compensate"] = ...,
    methods: Literal["all"] | str | Sequence[str] = ...,
    protocol: Literal["both", "paper", "causal"] = ..., split: float = ..., repeats: int = ...,
    horizon: int = ..., window: int = ..., mirror: float = ..., windows: int = ...,
    causal_ensemble: int = ..., progress: Callable[[float], object] | None = ...,
    **settings: Any,
) -> dict[str, Any]: ...

def fit_defaults() -> dict[str, Any]: ...

def calibrate(
    manifest_path: str | PathLike[str], output_dir: str | PathLike[str], *, force: bool = ...,
    threads: int = ..., progress: Callable[[float], object] | None = ...,
) -> dict[str, Any]: ...

def demo(
    output: str | PathLike[str] = ..., *, input: str | PathLike[str] | None = ...,
    target: str | None = ..., temperature: str | None = ..., rate_hz: float | None = ...,
    units: Literal["dph", "dps", "rads"] = ..., duration: float = ..., ensemble: int = ...,
    realisations: int = ..., window: int = ..., mirror: float = ..., windows: int = ...,
    causal_ensemble: int = ..., methods: str = ...,
    seed: int = ..., threads: int = ..., gaps: Literal["error", "interpolate"] = ...,
    progress: Callable[[float], object] | None = ...,
) -> dict[str, Any]: ...
