"""Fast single-object tracking in camera frames: template matching near the predicted position,
re-detection over the whole frame when the object is lost.

    tracker = Tracker.from_region(first_frame, (x, y, w, h), camera, height_m=0.3)   # a user's box
    tracker = Tracker(template_image, camera, width_m=0.24, height_m=0.3)           # or an image
    tracker = Tracker(bgra_cut_out, camera, height_m=0.3)             # or one without its background
    track = tracker.update(frame.image, frame.time_s)
    track.state, track.bearing_rad, track.range_m, track.confidence

Tracking (every frame): the object's box is predicted from its image velocity (plus, if given, the
robot's own rotation since the last frame, which moves everything sideways by fx * tan(angle)); a
window around it is cut out and scaled so the template's core is about `work_px` pixels across (the
cost stays flat with distance); the core is matched there with OpenCV's normalised cross-correlation
(grey plus chromaticity, mean removed per channel: appearance.py says why) at three scales, so the
box follows the object as it nears or recedes; every few frames the scale check (scale_check.py)
fits the first template at a wider ladder of sizes (and the size last tracked with confidence), so a
box left on a part of a plain object grows back to all of it. The core (appearance.py) is the whole
template for an image of the object, the central `region_core` of a user's box (whose corners are
background), the solid middle of a cut-out (BGRA, alpha on the object). The template adapts on
confident frames, anchored to the first one. A match keeps the track only if it is plausible: it
correlates (`accept`), its core still correlates with the first template (`anchor_accept`: a track
that slid onto the background fails this), and its colours are the object's (`colour`). A miss
coasts on the prediction for `lost_after` - 1 frames (a brief occlusion), never off the picture.

Re-detection (while lost, and at start-up from an image): ORB features of the template (a region's:
those on the object, inside its ellipse) matched to the frame's with a ratio test and a robust
homography (OpenCV's USAC: a frame without the object costs a millisecond, not RANSAC's 2000 tries),
as find_object_2d does; that needs texture, so when the template has too few features, the
homography fails or its candidate fails the checks below, a multi-scale correlation of the first
template's core over the whole (reduced) frame stands in, near the size last tracked with confidence
for a while. Either way a candidate is accepted only if the correlation at its box reaches
`accept_redetect`, stricter than what keeps a track alive, and its colours match (`colour_redetect`,
also stricter), so clutter does not get "re-acquired"; a cut-out's candidate must also fit its whole
figure (`figure_redetect`) with none of its colours round it (`surround_redetect`), so a look-alike
of another shape does not either. A cut-out's track that stops fitting its figure (`figure_keep`,
`surround_keep`, looser) for `misfit_s` is dropped (after `lost_after` - 1 frames of coasting): the
object went behind a look-alike and the match slid onto it.

States: TRACKING, LOST, and REACQUIRED on the first frame of a track found again by re-detection.
OpenCV is imported when a tracker is made (the `vision` extra).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from host_sdk.body import CameraModel
from host_sdk.errors import CommandRangeError
from host_sdk.extras import require
from host_sdk.perception.appearance import Appearance
from host_sdk.perception.boxes import Box, Image, centre, in_ellipse, near_same, subpixel_peak, visible_share
from host_sdk.perception.scale_check import best_size
from host_sdk.perception.template import cutout_core, on_cutout
from host_sdk.perception.tracker_params import TrackerParams

__all__ = ["Box", "Image", "Track", "TrackState", "Tracker", "TrackerParams"]


class TrackState(Enum):
    TRACKING = "tracking"
    LOST = "lost"
    REACQUIRED = "reacquired"


@dataclass(frozen=True, slots=True)
class Track:
    state: TrackState
    time_s: float
    box: Box | None
    """Where the object is (None when lost)."""
    confidence: float
    """Normalised correlation of the best match, -1..1 (0 when lost)."""
    bearing_rad: float | None
    """From the robot's forward axis, left positive (camera model and mount)."""
    range_m: float | None
    """Depth from the apparent size, when the object's size is known."""
    lost_s: float
    """How long the object has been lost (0 while tracked)."""

    @property
    def found(self) -> bool:
        return self.state is not TrackState.LOST

    @property
    def centre(self) -> tuple[float, float] | None:
        if self.box is None:
            return None
        x, y, w, h = self.box
        return x + w / 2, y + h / 2


MIN_MATCH_PX = 6
"""Re-detection's correlation never shrinks a template's core below this many pixels a side (a far
object's few pixels would no longer say what it is, and the box found would be the wrong size)."""


def _cv2() -> Any:
    return require("cv2", "vision", "the tracker")


class Tracker:
    def __init__(
        self,
        template: Image,
        camera: CameraModel,
        *,
        width_m: float | None = None,
        height_m: float | None = None,
        params: TrackerParams | None = None,
        box: Box | None = None,
        time_s: float = 0.0,
        core: float | None = None,
    ) -> None:
        if not (isinstance(template, np.ndarray) and template.ndim == 3 and template.shape[2] in (3, 4)):
            raise CommandRangeError(
                "template",
                getattr(template, "shape", template),
                "a BGR image (H x W x 3) or a BGRA cut-out (H x W x 4)",
            )
        p = params or TrackerParams()
        if min(template.shape[:2]) < p.min_size_px:
            raise CommandRangeError("template", template.shape[:2], f"at least {p.min_size_px} pixels on each side")
        self.cv2 = _cv2()
        self.camera = camera
        self.params = p
        # A cut-out (alpha: the object's pixels) is matched on the largest central part that is the
        # object; a plain image is all object; a user's region sets its own core.
        opaque = template[..., 3] >= 128 if template.shape[2] == 4 else None
        if opaque is not None and opaque.all():
            opaque = None  # an alpha that hides nothing: a plain image
        if opaque is not None and cutout_core(opaque) < 0.3:
            raise CommandRangeError(
                "template",
                f"a cut-out {float(opaque.mean()) * 100:.0f} % opaque",
                "a cut-out whose middle is the object (its alpha >= 128 there)",
            )
        if core is None:
            core = 1.0 if opaque is None else cutout_core(opaque)
        self.template = np.ascontiguousarray(template[..., :3])
        self.size_m = (width_m, height_m)
        if not 0.2 <= core <= 1.0:
            raise CommandRangeError("core", core, "0.2 to 1.0")
        self.look = Appearance(self.cv2, self.template, core, p.appearance, mask=opaque)
        self._orb = self.cv2.ORB_create(nfeatures=500, fastThreshold=10, edgeThreshold=11, patchSize=11)
        big = self.template
        if max(big.shape[:2]) < 120:  # enlarge small templates so ORB finds features on them
            f = 120 / max(big.shape[:2])
            big = self.cv2.resize(big, None, fx=f, fy=f, interpolation=self.cv2.INTER_LINEAR)
        else:
            f = 1.0
        kp, des = self._orb.detectAndCompute(self.cv2.cvtColor(big, self.cv2.COLOR_BGR2GRAY), None)
        if des is not None and (core < 1.0 or opaque is not None):  # keep the object's features
            keep = [
                i
                for i, k in enumerate(kp)
                if (in_ellipse(k.pt, big.shape) if opaque is None else on_cutout(opaque, k.pt, f))
            ]
            kp, des = [kp[i] for i in keep], (des[keep] if keep else None)
        self._tpl_kp = np.array([k.pt for k in kp], dtype=np.float32).reshape(-1, 2) / f
        self._tpl_des = des
        self._matcher = self.cv2.BFMatcher(self.cv2.NORM_HAMMING)
        self.box: Box | None = box
        self.scale = 1.0 if box is None else box[3] / template.shape[0]
        self.velocity = (0.0, 0.0)
        """Image velocity of the box centre, pixels per second."""
        self.time_s = time_s
        self.lost_since: float | None = None if box is not None else time_s
        self._misses = 0
        self._phase = 0
        self._shift = 0.0
        self._first = True
        self._misfit_s = 0.0
        """How long the track has not fitted its figure (`_misfits`)."""
        self._seen_s: float | None = None if box is None else time_s
        self._sure: tuple[float, float, float] | None = None if box is None else (box[2], box[3], time_s)
        """Width, height and time of the last confident frame's box (`_confident`)."""
        self._found_s: float | None = None
        """When the track was last re-detected."""
        self._frames = 0

    @classmethod
    def from_region(cls, image: Image, box: Box, camera: CameraModel, **kwargs: Any) -> Tracker:
        """Track what is inside `box` (x, y, w, h) of `image` (a user's selection)."""
        x, y, w, h = (round(v) for v in box)
        H, W = image.shape[:2]
        if not (x >= 0 and y >= 0 and w > 0 and h > 0 and x + w <= W and y + h <= H):
            raise CommandRangeError("box", box, f"a region inside the {W}x{H} image")
        kwargs.setdefault("core", (kwargs.get("params") or TrackerParams()).region_core)
        return cls(image[y : y + h, x : x + w].copy(), camera, box=(x, y, w, h), **kwargs)

    @property
    def has_features(self) -> bool:
        return self._tpl_des is not None and len(self._tpl_kp) >= 8

    # -- the per-frame step -------------------------------------------------------------------------
    def update(self, image: Image, time_s: float, *, rotation_rad: float = 0.0) -> Track:
        """Find the object in `image` (taken at `time_s`); `rotation_rad`: how far the camera turned
        (counter-clockwise) since the previous frame, if known."""
        dt = max(0.0, time_s - self.time_s)
        self.time_s = time_s
        if self.box is None:  # the first frame of a tracker started from an image tries every scale
            first, self._first = self._first, False
            return self._redetect(image, time_s, every_scale=first)
        self._first = False
        pred = self._predict(dt, rotation_rad)
        found = self._match_near(image, pred)
        agree = self.look.agreement(image, found[0]) if found is not None else 0.0
        if found is not None and self._plausible(image, found, agree) and not self._misfits(image, found[0], dt):
            box, score = found
            self._frames += 1
            matched = box
            if self._frames % self.params.scale_check_every == 0:
                box = self._rescale(image, box, shrink=score >= self.params.scale_check_above)
            self._accept(box, dt)
            # The score and agreement are the matched box's: a box resized here is neither a sure
            # size nor taught to the template until a frame matches it at that size.
            if box == matched:
                self._confident(box, score, agree)
                if self._misfit_s == 0.0:  # a frame that does not fit the figure teaches nothing
                    self.look.learn(image, box, score, agree)
            self._misses = 0
            return self._track(TrackState.TRACKING, score)
        self._misses += 1
        if self._misses < self.params.lost_after and visible_share(pred, image) >= 0.5:
            self.box = pred  # coast on the prediction through a brief occlusion (not off the picture)
            return self._track(TrackState.TRACKING, found[1] if found else 0.0)
        self.box = None
        self.lost_since = time_s
        self.velocity = (0.0, 0.0)
        return self._redetect(image, time_s)

    def _plausible(self, image: Image, found: tuple[Box, float], agree: float) -> bool:
        """A match good enough to keep the track: it correlates, it still resembles the first
        template, and its colours are the object's (a look-alike patch of background fails one)."""
        p = self.params
        return found[1] >= p.accept and agree >= p.anchor_accept and self.look.colour_match(image, found[0]) >= p.colour

    def _misfits(self, image: Image, box: Box, dt: float) -> bool:
        """True once a cut-out's track has not fitted its whole figure for `misfit_s`: it slid onto
        a look-alike that shares the figure's middle (a cylinder in its stripes that hid it). The
        match and its colours cannot say so; the figure's outline can. Partly off the picture the
        figure cannot be seen whole: the count pauses there."""
        p = self.params
        if not self.look.sees_whole(image, box):
            return self._misfit_s >= p.misfit_s
        if self.look.fits_figure(image, box, p.figure_keep, p.surround_keep):
            self._misfit_s = 0.0
            return False
        self._misfit_s += dt
        return self._misfit_s >= p.misfit_s

    def _confident(self, box: Box, score: float, agree: float) -> None:
        """Remember the box's size if the frame is one the template learns from (`Appearance.learn`),
        but not for `redetect_near_s` after a re-detection: its box may be on a part of the object."""
        a = self.params.appearance
        held = self._found_s is not None and self.time_s - self._found_s < self.params.redetect_near_s
        if score >= a.learn_above and agree >= a.anchor_agree and not held:
            self._sure = (box[2], box[3], self.time_s)

    def _predict(self, dt: float, rotation_rad: float) -> Box:
        assert self.box is not None
        x, y, w, h = self.box
        shift = self.camera.fx * math.tan(rotation_rad) if rotation_rad else 0.0
        self._shift = shift
        vx, vy = self.velocity
        return (x + vx * dt + shift, y + vy * dt, w, h)

    def _accept(self, box: Box, dt: float) -> None:
        if self.box is not None and dt > 0:
            (ox, oy), (nx, ny) = centre(self.box), centre(box)
            # The object's own image motion: the camera's turn (the prediction's shift) is not repeated.
            vx, vy = (nx - ox - self._shift) / dt, (ny - oy) / dt
            a = 0.5  # smoothing: a box jitters by a pixel or so from frame to frame
            self.velocity = (a * vx + (1 - a) * self.velocity[0], a * vy + (1 - a) * self.velocity[1])
        self.box = box
        self.scale = box[3] / self.template.shape[0]
        self.lost_since = None
        self._seen_s = self.time_s

    def _track(self, state: TrackState, score: float) -> Track:
        box = self.box
        assert box is not None
        x, _, w, h = box
        cam = self.camera
        width_m, height_m = self.size_m
        depth = cam.range_from_size(w_px=w, h_px=h, width_m=width_m, height_m=height_m)
        bearing = cam.bearing(x + w / 2)
        rng = None if depth is None else depth / max(math.cos(bearing - cam.mount_yaw_rad), 1e-6)
        return Track(state, self.time_s, box, float(score), bearing, rng, 0.0)

    def _lost(self, time_s: float) -> Track:
        since = self.lost_since if self.lost_since is not None else time_s
        return Track(TrackState.LOST, time_s, None, 0.0, None, None, time_s - since)

    # -- matching -----------------------------------------------------------------------------------
    def _match_near(self, image: Image, pred: Box) -> tuple[Box, float] | None:
        """Best box near `pred` over three scales, and its correlation."""
        cv2, p = self.cv2, self.params
        H, W = image.shape[:2]
        x, y, w, h = pred
        if not (p.min_size_px <= min(w, h) and max(w / W, h / H) <= 2.0) or visible_share(pred, image) <= 0.0:
            return None  # not an object this camera can show (a degenerate homography's box)
        m = p.search
        big = p.scale_step
        wx0, wy0 = int(x - m * w * big), int(y - m * h * big)
        wx1, wy1 = math.ceil(x + w * (1 + m) * big), math.ceil(y + h * (1 + m) * big)
        x0, y0, x1, y1 = max(0, wx0), max(0, wy0), min(W, wx1), min(H, wy1)
        if x1 - x0 < p.min_size_px or y1 - y0 < p.min_size_px:
            return None
        f = min(1.0, p.work_px / (max(w, h) * self.look.core))  # the core is matched at work_px
        window = image[y0:y1, x0:x1]
        # An object near the frame's edge may hang over it (close up, a tall target's top is cut):
        # the window is extended by repeating the edge, up to half the box, so it can still be matched
        # (the part outside matches poorly, so only a mostly visible object passes).
        pads = (min(y0 - wy0, h // 2), min(wy1 - y1, h // 2), min(x0 - wx0, w // 2), min(wx1 - x1, w // 2))
        if any(pads):
            top, bottom, left, right = (int(v) for v in pads)
            window = cv2.copyMakeBorder(window, top, bottom, left, right, cv2.BORDER_REPLICATE)
            x0, y0 = x0 - left, y0 - top
        if f < 1.0:
            window = cv2.resize(window, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
        space = self.look.space(window)
        best = self._scan(space, f, (x0, y0), (w, h), anchor=False)
        if best is None or best[1] < p.accept:  # the adaptive template may have drifted: the first one
            first = self._scan(space, f, (x0, y0), (w, h), anchor=True)
            if first is not None and (best is None or first[1] > best[1]):
                best = first
        return best

    def _scan(
        self, window: NDArray[np.float32], f: float, origin: tuple[int, int], size: tuple[float, float], *, anchor: bool
    ) -> tuple[Box, float] | None:
        """The template's core at three scales round `size` over `window` (reduced by f): best box.
        The middle scale searches the whole window; the other two only round its peak (a 6 % change
        of size moves the peak by a pixel or two), which makes a frame about twice as cheap."""
        big, core = self.params.scale_step, self.look.core
        best: tuple[Box, float] | None = None
        peak: tuple[int, int, int, int] | None = None  # the middle scale's x, y, w, h in the window
        for s in (1.0, 1 / big, big):
            tw, th = round(size[0] * s * core * f), round(size[1] * s * core * f)
            if tw < 4 or th < 4 or tw > window.shape[1] or th > window.shape[0]:
                continue
            x0 = y0 = 0
            area = window
            if peak is not None:
                r = 3  # pixels of slack round the peak, in the reduced window
                px, py, pw, ph = peak
                x0 = max(0, min(px + (pw - tw) // 2 - r, window.shape[1] - tw))
                y0 = max(0, min(py + (ph - th) // 2 - r, window.shape[0] - th))
                area = window[y0 : y0 + th + 2 * r, x0 : x0 + tw + 2 * r]
            res = self.cv2.matchTemplate(area, self.look.template(tw, th, anchor=anchor), self.cv2.TM_CCOEFF_NORMED)
            _, score, _, loc = self.cv2.minMaxLoc(res)
            if s == 1.0:
                peak = (loc[0], loc[1], tw, th)
            if best is None or score > best[1]:
                dx, dy = subpixel_peak(res, loc)
                bw, bh = tw / f / core, th / f / core
                bx = (x0 + loc[0] + dx) / f + origin[0] - bw * (1 - core) / 2
                by = (y0 + loc[1] + dy) / f + origin[1] - bh * (1 - core) / 2
                best = ((bx, by, bw, bh), float(score))
        return best

    def _rescale(self, image: Image, box: Box, *, shrink: bool) -> Box:
        """`box` at the size the first template fits best (scale_check.py): a few sizes either side
        (smaller ones only if `shrink`) and, for `redetect_near_s` after it, the size last tracked
        with confidence, if bigger (a box re-detected on a part of the object grows back)."""
        p = self.params
        k, step = p.scale_check_steps, p.scale_check_step
        scales = [step**i for i in range(-k if shrink else 0, k + 1)]
        if self._sure is not None and self.time_s - self._sure[2] < p.redetect_near_s:
            ref = self._sure[1] / box[3]
            scales += [ref * step**i for i in (-1, 0, 1) if ref * step**i > scales[-1] * 1.02]
        return best_size(self.cv2, self.look, image, box, scales, work_px=p.work_px, margin=p.scale_check_margin)

    def detect(self, image: Image, time_s: float) -> Track:
        """A detection from scratch over the whole frame at every scale at once (what `update` spreads
        over a few frames while lost): REACQUIRED with the box, or LOST. The track starts from it."""
        self.box = None
        self.time_s = time_s
        return self._redetect(image, time_s, every_scale=True)

    def _redetect(self, image: Image, time_s: float, *, every_scale: bool = False) -> Track:
        p = self.params
        # The features' candidate first; if there is none, or it fails the checks (a homography from
        # a few matches, half of them past the frame's edge, places a box badly), the correlation's.
        tried: list[Box] = []
        for find in ("features", "correlation"):
            if find == "features":
                box = self._detect_features(image) if self.has_features else None
            else:
                box = self._detect_correlation(image, every_scale=every_scale)
            refined = None if box is None else self._match_near(image, box)
            if refined is not None:
                refined = (self._rescale(image, refined[0], shrink=False), refined[1])
            if refined is None or any(near_same(refined[0], other) for other in tried):
                continue
            tried.append(refined[0])
            if (
                refined[1] >= p.accept_redetect
                and self.look.colour_match(image, refined[0]) >= p.colour_redetect
                and self.look.fits_figure(image, refined[0], p.figure_redetect, p.surround_redetect)
            ):
                self.box = None
                self._accept(refined[0], 0.0)
                self.velocity = (0.0, 0.0)
                self._misses = 0
                self._misfit_s = 0.0
                self._found_s = None if self._sure is None else time_s  # a first detection holds nothing
                return self._track(TrackState.REACQUIRED, refined[1])
        return self._lost(time_s)

    def _detect_features(self, image: Image) -> Box | None:
        cv2 = self.cv2
        gray = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        kp, des = self._orb.detectAndCompute(gray, None)
        if des is None or len(kp) < 8:
            return None
        pairs = self._matcher.knnMatch(self._tpl_des, des, k=2)
        good = [m[0] for m in pairs if len(m) == 2 and m[0].distance < 0.8 * m[1].distance]
        if len(good) < 8:
            return None
        src = self._tpl_kp[[m.queryIdx for m in good]].reshape(-1, 1, 2)
        dst = np.array([kp[m.trainIdx].pt for m in good], dtype=np.float32).reshape(-1, 1, 2)
        hom, inliers = cv2.findHomography(src, dst, cv2.USAC_DEFAULT, 4.0)
        if hom is None or int(inliers.sum()) < 8:
            return None
        th, tw = self.template.shape[:2]
        corners = np.array([[0, 0], [tw, 0], [tw, th], [0, th]], dtype=np.float32).reshape(-1, 1, 2)
        pts = cv2.perspectiveTransform(corners, hom).reshape(-1, 2)
        x0, y0 = pts.min(axis=0)
        x1, y1 = pts.max(axis=0)
        w, h = float(x1 - x0), float(y1 - y0)
        if w < self.params.min_size_px or h < self.params.min_size_px or not np.isfinite(pts).all():
            return None
        found = (float(x0), float(y0), w, h)
        if max(w / image.shape[1], h / image.shape[0]) > 2.0 or visible_share(found, image) < 0.5:
            return None  # a homography from a few clustered matches can throw the box anywhere
        # A homography of a template onto a rigid object keeps its aspect ratio roughly.
        if not 0.5 < (w / h) / (tw / th) < 2.0:
            return None
        return float(x0), float(y0), w, h

    def _detect_correlation(self, image: Image, *, every_scale: bool = False) -> Box | None:
        """Multi-scale correlation over the whole frame, each scale on a copy reduced so the template
        is about work_px across (small scales at full resolution)."""
        cv2, p = self.cv2, self.params
        th, tw = self.template.shape[:2]
        H, W = image.shape[:2]
        reduced: dict[float, NDArray[np.float32]] = {}
        best: tuple[float, Box] | None = None
        lo, hi, n = p.redetect_scales
        if not every_scale and self._sure is not None and self.time_s - self._sure[2] < p.redetect_near_s:
            ref, k = self._sure[1] / th, p.redetect_near
            lo, hi, n = max(lo, ref / k), min(hi, ref * k), max(2, n // 2)
        elif not every_scale and self._seen_s is not None and self.time_s - self._seen_s < p.redetect_near_s:
            lo, hi, n = max(lo, self.scale / 2), min(hi, self.scale * 2), max(2, n // 2)  # never confident
        scales = np.geomspace(lo, hi, n)
        rounds = 1 if every_scale else math.ceil(scales.shape[0] / p.redetect_per_frame)
        self._phase %= rounds
        turn = np.arange(self._phase, scales.shape[0], rounds)
        self._phase += 1
        for s in scales[turn]:
            w, h = tw * s, th * s
            if w > W or h > H or min(w, h) < p.min_size_px:
                continue
            full = min(1.0, p.work_px / max(w, h))
            f = min(p.redetect_max_zoom, full)
            if min(w, h) * self.look.core * f < MIN_MATCH_PX:
                f = max(f, min(full, MIN_MATCH_PX / (min(w, h) * self.look.core)))  # a far object stays matchable
            f = round(f, 2)
            frame = reduced.get(f)
            if frame is None:
                frame = self.look.space(
                    image if f == 1.0 else cv2.resize(image, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
                )
                reduced[f] = frame
            core = self.look.core
            tw_f, th_f = max(4, round(w * core * f)), max(4, round(h * core * f))
            if tw_f > frame.shape[1] or th_f > frame.shape[0]:
                continue
            res = cv2.matchTemplate(frame, self.look.template(tw_f, th_f, anchor=True), cv2.TM_CCOEFF_NORMED)
            _, score, _, loc = cv2.minMaxLoc(res)
            if best is None or score > best[0]:
                bw, bh = tw_f / f / core, th_f / f / core
                box = (loc[0] / f - bw * (1 - core) / 2, loc[1] / f - bh * (1 - core) / 2, bw, bh)
                best = (float(score), box)
        if best is None or best[0] < p.accept:
            return None
        return best[1]
