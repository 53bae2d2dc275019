"""Signals: the Trajectory data type, Butterworth filtering, detrending, resampling."""

from .filters import apply_sos as apply_sos
from .filters import bandpass as bandpass
from .filters import butter_ba as butter_ba
from .filters import butter_sos as butter_sos
from .filters import butter_zpk as butter_zpk
from .filters import highpass as highpass
from .filters import lowpass as lowpass
from .processing import ac_couple as ac_couple
from .processing import decimate as decimate
from .processing import detrend as detrend
from .processing import remove_mean as remove_mean
from .processing import resample as resample
from .processing import segment_by as segment_by
from .processing import split as split
from .processing import to_uniform as to_uniform
from .trajectory import Trajectory as Trajectory
