"""The tracker's tunables (`TrackerParams`), each with what it was measured against."""

from __future__ import annotations

from dataclasses import dataclass, field

from host_sdk.perception.appearance import AppearanceParams


@dataclass(frozen=True, slots=True)
class TrackerParams:
    work_px: int = 28
    """Template size (largest side, pixels) the matching runs at."""
    search: float = 1.0
    """Search window margin around the predicted box, in box sizes."""
    scale_step: float = 1.06
    scale_check_every: int = 3
    """Every this many tracked frames the scale check (scale_check.py) runs: it keeps a plain
    object's box from staying on a part of it (small-plain kept 45 % of its frames without it, 89 %
    with it), at a tenth to a third of a frame's cost each time."""
    scale_check_steps: int = 3
    """The check tries this many sizes either side of the box's, `scale_check_step` apart."""
    scale_check_step: float = 1.1
    scale_check_margin: float = 0.02
    """Correlation by which another size must beat the box's own for the check to move it."""
    scale_check_above: float = 0.85
    """The check shrinks a box only on a frame whose match reaches this: a pole in front lowers
    the score, and a part of the object beside it fits better than the whole (the hard scene's cup
    kept 55 % of its frames instead of 82 % when it shrank at any score)."""
    accept: float = 0.5
    """Correlation that keeps a track alive."""
    accept_redetect: float = 0.72
    """Correlation a re-detected candidate must reach."""
    lost_after: int = 2
    """Consecutive frames below `accept` before the track is declared lost."""
    min_size_px: int = 6
    redetect_scales: tuple[float, float, int] = (0.15, 2.5, 12)
    """Scales the correlation fallback tries: smallest, largest (times the template), how many. A
    template taken at 0.8 m covers 0.3 m to 5 m this way."""
    redetect_per_frame: int = 4
    """Of those, how many one frame tries (in turn: all are covered every few frames while lost)."""
    redetect_max_zoom: float = 0.5
    """The correlation fallback's frame is at most this share of full size (a small object's
    candidate is refined at full size before it is accepted): what a lost frame costs."""
    anchor_accept: float = 0.3
    """Correlation of the match's core with the first template that a track needs: a track that slid
    onto the background (the adaptive template with it) scores high against itself, not against this."""
    redetect_near_s: float = 3.0
    """For this long after the last confident frame (one the template learns from), the correlation
    fallback looks for the object within `redetect_near` of the size it had then, and the scale check
    tries that size too: it cannot have changed much, and a part of it must not pass for it. That
    size is not updated for this long after a re-detection (its box may be on such a part)."""
    redetect_near: float = 1.3
    """See `redetect_near_s`: a plain cup's part at 0.6 of its size correlated 0.8, enough to pass."""
    region_core: float = 0.6
    """Share of each side of a user's box (`from_region`) that is matched: its corners are background."""
    colour: float = 0.55
    """Colour agreement (1 - Bhattacharyya distance of hue-saturation histograms) of the match's core
    with the first template's, to keep a track."""
    colour_redetect: float = 0.6
    """The same, to re-detect one: stricter, as `accept_redetect` is (a warm patch of background
    scored 0.55 against a red cup's 0.66 and more)."""
    figure_redetect: float = 0.85
    """A cut-out template's correlation over its whole figure (`figure_match`) that a re-detected
    candidate must reach: on the photographic emulator camera the target scored 0.84-0.97 (0.82-0.85
    close up and lit from the side), a cylinder painted in its stripes (sky where the figure's head
    is) 0.70-0.84."""
    surround_redetect: float = 0.3
    """At most this much may what surrounds a cut-out's figure in a re-detected box have the
    object's colours (`surround_match`): the target scored at most 0.29, the inside of a wide
    cylinder in its stripes, close up, 0.37 and more. Tuned on the emulator's figure only: on real
    photos an object before a background of much its colours can score more (docs/autonomy.md)."""
    figure_keep: float = 0.75
    """A tracked cut-out whose whole-figure fit stays below this (or whose surround stays above
    `surround_keep`) for `misfit_s` is dropped. Looser than re-detection's: tracking follows the
    object through turns and shading (the target scored 0.83 and more in 99 % of its tracked frames
    on the photographic camera, 0.63 at worst)."""
    surround_keep: float = 0.45
    """See `figure_keep`: the target standing before a cylinder in its stripes scored up to 0.54; a
    track on such a cylinder itself 0.53-0.78 for as long as it lasted."""
    misfit_s: float = 1.5
    """How long a cut-out's track may not fit its figure before it is dropped: the longest such
    stretch on the target was 0.9 s; four tracks that had slid onto a cylinder lasted 5-35 s."""
    appearance: AppearanceParams = field(default_factory=AppearanceParams)
