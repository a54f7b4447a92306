"""The tracker's model of what the object looks like: a template matched on the object's core, an
adaptive copy anchored to the first one, and a colour signature.

Why the core: a user's box round a real object holds background in its corners (nothing is a
rectangle), and that background changes as the object moves; correlating the whole box, those
corners drag the score down until the track is dropped. Matching the central part of the box (the
`core` fraction of each side, 0.6 by default for a region, the whole template for an image that is
only the object) keeps the score on the object. A core with too little contrast to correlate (a
plain object) is widened back towards the whole box, whose edges then carry the match.

Why two templates: the object's look drifts (it turns, the light changes), so the template follows
it on confident frames (a running blend); a blend can slide onto the background, so it is only
updated where the first template (the anchor) still agrees, and it is reset to the anchor when the
two part. Matching falls back to the anchor when the adaptive template scores low.

Why grey plus chromaticity: a surface turned another way to the light is darker or brighter, and
the shading changes its grey pattern (a figure lit from the side correlates 0.3 with its photo
lit from the front, in grey); shading scales a pixel's three channels alike, so the shares of blue
and green in it (chromaticity) do not change. Correlation runs on grey and those two shares
(`match_space`): the grey keeps a plain or grey object's edges, the chromaticity keeps a coloured
one's pattern under any light. This is the colour-attributes idea of the DCF family (KCF-CN).

Why a mask: a cut-out (a photo with its background removed) says which pixels are the object. Its
colour signature counts only those, and a candidate box is measured over the same pixels, so the
colours of whatever stands behind the object (a brick wall, another one's background) count for
nothing on either side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

Image = NDArray[np.uint8]
Box = tuple[float, float, float, float]


@dataclass(frozen=True, slots=True)
class AppearanceParams:
    learn_rate: float = 0.08
    """Weight of a new confident frame in the adaptive template."""
    learn_above: float = 0.85
    """Correlation a frame needs before the template learns from it."""
    anchor_agree: float = 0.6
    """Correlation the frame's core must have with the first template for the template to learn."""
    reset_below: float = 0.5
    """Adaptive and first template this far apart (correlation): back to the first."""
    min_contrast: float = 10.0
    """Grey-level standard deviation a core needs to be matched alone."""
    hist_bins: tuple[int, int] = (16, 8)
    """Hue and saturation bins of the colour signature."""


class Appearance:
    def __init__(
        self,
        cv2: Any,
        template: Image,
        core: float,
        params: AppearanceParams | None = None,
        *,
        mask: NDArray[np.bool_] | None = None,
    ) -> None:
        if mask is not None:
            mask = np.asarray(mask, dtype=bool)
            if mask.shape != template.shape[:2]:
                raise ValueError(f"mask: shape {mask.shape}, the template's is {template.shape[:2]}")
        self.cv2 = cv2
        self.params = params or AppearanceParams()
        self.anchor = np.ascontiguousarray(template)
        self.current = self.anchor.copy()
        self.core = self._core_for(core)
        self._cache: dict[tuple[int, int, bool], NDArray[np.float32]] = {}
        self._anchor_space: NDArray[np.float32] | None = None
        self.chroma_weight = chroma_weight(cv2, self.core_of(self.anchor))
        """How much the colour shares count beside grey in `match_space` (see chroma_weight)."""
        self.mask = None if mask is None else np.where(mask, 255, 0).astype(np.uint8)
        """The object's pixels of a cut-out template (255), or None: all of it."""
        self._figure_at = mask
        self._figure: NDArray[np.float32] | None = None
        """A cut-out's figure in match space, mean removed (the pixels of `mask`)."""
        self._figure_norm = 0.0
        self._figure_space: NDArray[np.float32] | None = None
        """The cut-out in match space (for a figure partly off the picture)."""
        self._surround: NDArray[np.uint8] | None = None
        """A cut-out's background pixels at least three pixels from the figure's edge (255)."""
        if mask is not None and mask.any():
            self._surround = cv2.erode(np.where(mask, 0, 255).astype(np.uint8), np.ones((5, 5), np.uint8))
            self._figure_space = self.space(self.anchor)
            figure = self._figure_space[mask]
            figure -= figure.mean(axis=0)
            # A figure with too little contrast of its own (a plain cup) has no pattern to check:
            # correlating it would correlate noise.
            if float(figure.std(axis=0).max()) >= self.params.min_contrast:
                self._figure = figure
                self._figure_norm = float((figure * figure).sum())
        self.signature = self.histogram(self.core_of(self.anchor), self._mask_core(self.anchor.shape))

    def _core_for(self, core: float) -> float:
        """Widen the core until it has contrast enough to correlate (a plain object's edges)."""
        gray = self.cv2.cvtColor(self.anchor, self.cv2.COLOR_BGR2GRAY)
        c = core
        while c < 1.0 and float(self.core_of(gray, c).std()) < self.params.min_contrast:
            c = min(1.0, c + 0.1)
        return c

    def core_of(self, image: NDArray[Any], core: float | None = None) -> NDArray[Any]:
        c = self.core if core is None else core
        h, w = image.shape[:2]
        dx, dy = round(w * (1 - c) / 2), round(h * (1 - c) / 2)
        return image[dy : h - dy, dx : w - dx]

    def inset(self, w: float, h: float) -> tuple[float, float, float, float]:
        """The core's offset and size inside a box of w x h."""
        c = self.core
        return w * (1 - c) / 2, h * (1 - c) / 2, w * c, h * c

    def template(self, w: int, h: int, *, anchor: bool = False) -> NDArray[np.float32]:
        """The core of the (adaptive or first) template at w x h pixels, in `match_space`."""
        key = (w, h, anchor)
        tpl = self._cache.get(key)
        if tpl is None:
            if len(self._cache) > 256:
                self._cache.clear()
            src = self.core_of(self.anchor if anchor else self.current)
            tpl = self.space(self.cv2.resize(src, (w, h), interpolation=self.cv2.INTER_AREA))
            self._cache[key] = tpl
        return tpl

    def histogram(self, image: Image, mask: NDArray[np.uint8] | None = None) -> NDArray[np.float32]:
        cv2 = self.cv2
        hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)
        hist = cv2.calcHist([hsv], [0, 1], mask, list(self.params.hist_bins), [0, 180, 0, 256])
        return np.asarray(cv2.normalize(hist, None, 1.0, 0.0, cv2.NORM_L1), dtype=np.float32)

    def _mask_core(self, shape: tuple[int, ...]) -> NDArray[np.uint8] | None:
        """The cut-out's mask over the core of an image of `shape` (None: no mask)."""
        if self.mask is None:
            return None
        mask = self.cv2.resize(self.mask, (shape[1], shape[0]), interpolation=self.cv2.INTER_NEAREST)
        return np.ascontiguousarray(self.core_of(mask))

    def colour_match(self, image: Image, box: Box) -> float:
        """1 - Bhattacharyya distance between the box's core colours and the first template's (a
        cut-out's: over the object's own pixels)."""
        patch = _crop(image, box, whole=self.mask is not None)
        if patch is None:
            patch = _crop(image, box)
            if patch is None:
                return 0.0
            mask = None  # part off the picture: the mask's pixels do not line up, count all
        else:
            mask = self._mask_core(patch.shape)
        return self._like_signature(self.histogram(np.ascontiguousarray(self.core_of(patch)), mask))

    def figure_match(self, image: Image, box: Box) -> float:
        """A cut-out's correlation with `box` over its whole figure, head and shoulders included
        (1.0 without a cut-out or for a plain figure). The core the search matches is the figure's
        solid middle, which a look-alike of another shape can share (a cylinder in the figure's
        stripes); the figure's head and shoulders it cannot. Measured at the box as found:
        searching a few sizes and shifts round it fitted the look-alikes better too (the PiCar's
        time with the target in view fell from 89 % to 79 % over 37 worlds). A box partly off the
        picture at the side is measured over the figure's pixels inside it, if at least
        FIGURE_SEEN of them are (a close target at the edge of the view); else 0 (`_seen_part`)."""
        if self._figure is None or self._figure_at is None:
            return 1.0
        part = self._seen_part(image, box)
        if part is None:
            return 0.0
        patch, (rows, cols), whole = part
        at = self._figure_at[rows, cols]
        if not whole and np.count_nonzero(at) < FIGURE_SEEN * np.count_nonzero(self._figure_at):
            return 0.0
        size = (cols.stop - cols.start, rows.stop - rows.start)
        seen = self.space(self.cv2.resize(patch, size, interpolation=self.cv2.INTER_AREA))[at]
        seen -= seen.mean(axis=0)
        figure, figure_norm = self._figure, self._figure_norm
        if not whole:
            assert self._figure_space is not None
            figure = self._figure_space[rows, cols][at]
            figure -= figure.mean(axis=0)
            figure_norm = float((figure * figure).sum())
        norm = math.sqrt(float((seen * seen).sum()) * figure_norm)
        return float((seen * figure).sum() / norm) if norm > 0 else 0.0

    def surround_match(self, image: Image, box: Box) -> float:
        """How much what surrounds a cut-out's figure inside `box` (its background pixels, away from
        the edge) has the object's colours, as `colour_match` measures; 0 without a cut-out. The
        object stands before something else; the inside of a bigger look-alike (a wide cylinder in
        the figure's stripes, close up) has the object's colours there too. Over the part of the
        box inside the picture, as `figure_match`; 0 if the box is cut at the top or the bottom."""
        part = self._seen_part(image, box)
        if self._surround is None or part is None:
            return 0.0
        patch, (rows, cols), _ = part
        size = (patch.shape[1], patch.shape[0])
        surround = self.cv2.resize(
            np.ascontiguousarray(self._surround[rows, cols]), size, interpolation=self.cv2.INTER_NEAREST
        )
        if int(np.count_nonzero(surround)) < 16:
            return 0.0  # too few pixels to say
        return self._like_signature(self.histogram(np.ascontiguousarray(patch), surround))

    def _seen_part(self, image: Image, box: Box) -> tuple[Image, tuple[slice, slice], bool] | None:
        """The box's pixels inside the picture, the same part of the template (rows and columns at
        the template's size) and whether that is all of it. A box cut at the frame's left or right
        edge only: cut at the top or the bottom (or only a sliver inside), None. A figure's head, the
        part a look-alike lacks, is what a box past the top edge loses."""
        th, tw = self.anchor.shape[:2]
        patch = _crop(image, box, whole=True)
        if patch is not None:
            return patch, (slice(0, th), slice(0, tw)), True
        patch = _crop(image, box)
        x, y, w, h = box
        if patch is None or w <= 0 or h <= 0:
            return None
        x0, y0 = max(0, round(x)), max(0, round(y))
        u0, v0 = max(0, round((x0 - x) * tw / w)), max(0, round((y0 - y) * th / h))
        u1 = min(tw, round((x0 + patch.shape[1] - x) * tw / w))
        v1 = min(th, round((y0 + patch.shape[0] - y) * th / h))
        if u1 - u0 < 4 or v0 > 0 or v1 < th:
            return None  # cut at the top or the bottom: the outline that tells look-alikes apart may be gone
        return patch, (slice(v0, v1), slice(u0, u1)), False

    def sees_whole(self, image: Image, box: Box) -> bool:
        """`box` lies inside the picture (the figure can be seen whole)."""
        return _crop(image, box, whole=True) is not None

    def fits_figure(self, image: Image, box: Box, figure_min: float, surround_max: float) -> bool:
        """A cut-out's whole figure at `box` fits (`figure_match` >= `figure_min`) with none of its
        colours round it (`surround_match` <= `surround_max`); always True without a cut-out."""
        return self.figure_match(image, box) >= figure_min and self.surround_match(image, box) <= surround_max

    def _like_signature(self, hist: NDArray[np.float32]) -> float:
        """1 - Bhattacharyya distance between `hist` and the first template's colours."""
        return 1.0 - float(self.cv2.compareHist(self.signature, hist, self.cv2.HISTCMP_BHATTACHARYYA))

    def agreement(self, image: Image, box: Box) -> float:
        """Correlation of the box's core with the first template's (how much the track drifted)."""
        patch = _crop(image, box, whole=True)
        if patch is None:
            return 1.0  # part off the picture: not measurable here, the match itself decided
        th, tw = self.anchor.shape[:2]
        patch = self.cv2.resize(patch, (tw, th), interpolation=self.cv2.INTER_AREA)
        return self._to_anchor(patch)

    def learn(self, image: Image, box: Box, score: float, agreement: float) -> None:
        """Blend the object's look at `box` into the adaptive template, if the frame is trustworthy:
        a high `score` and an `agreement` with the first template (see `agreement`)."""
        p = self.params
        if score < p.learn_above or agreement < p.anchor_agree:
            return
        patch = _crop(image, box, whole=True)
        if patch is None:
            return
        th, tw = self.anchor.shape[:2]
        patch = self.cv2.resize(patch, (tw, th), interpolation=self.cv2.INTER_AREA)
        blend = self.cv2.addWeighted(self.current, 1 - p.learn_rate, patch, p.learn_rate, 0.0)
        if self._to_anchor(blend) < p.reset_below:
            blend = self.anchor.copy()
        self.current = blend
        self._cache = {k: v for k, v in self._cache.items() if k[2]}

    def space(self, image: Image) -> NDArray[np.float32]:
        """`image` in this object's `match_space`."""
        return match_space(self.cv2, image, self.chroma_weight)

    def _to_anchor(self, image: Image) -> float:
        """Correlation of `image`'s core (template-sized) with the first template's core (whose
        match space is computed once)."""
        if self._anchor_space is None:
            self._anchor_space = self.space(np.ascontiguousarray(self.core_of(self.anchor)))
        core = self.space(np.ascontiguousarray(self.core_of(image)))
        return float(self.cv2.matchTemplate(core, self._anchor_space, self.cv2.TM_CCOEFF_NORMED).max())


def match_space(cv2: Any, image: Image, chroma_weight: float = 1.0) -> NDArray[np.float32]:
    """What correlation compares: grey and the blue and green shares of each pixel (0-255 times
    `chroma_weight`; CHROMA_FLOOR keeps a dark pixel's noise from looking like a strong colour).
    OpenCV's per-pixel operations: this runs on every frame's search window."""
    b, g, r = cv2.split(image.astype(np.float32))
    total = cv2.add(cv2.add(b, g), r) + 3 * CHROMA_FLOOR
    k = 255.0 * chroma_weight
    shares = (cv2.divide(b + CHROMA_FLOOR, total, scale=k), cv2.divide(g + CHROMA_FLOOR, total, scale=k))
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY).astype(np.float32)
    return np.asarray(cv2.merge([grey, *shares]), dtype=np.float32)


CHROMA_FLOOR = 8.0
FIGURE_SEEN = 0.6
"""The share of a cut-out's figure a box partly off the picture must show to be judged by it."""


def chroma_weight(cv2: Any, template: Image) -> float:
    """The colour shares' weight for a template: the contrast of its shares relative to its grey
    contrast, at most 1. A coloured pattern (stripes of two paints) is carried by its shares and
    they count fully; a mostly grey object (a cup, a face) keeps grey in charge, where a colourful
    background's shares would otherwise only add noise to the correlation."""
    shares = match_space(cv2, template)[..., 1:]
    grey = float(cv2.cvtColor(template, cv2.COLOR_BGR2GRAY).std())
    return min(1.0, math.sqrt(float(shares.var(axis=(0, 1)).sum())) / max(grey, 1.0))


def _crop(image: Image, box: Box, *, whole: bool = False) -> Image | None:
    """The box's pixels; with `whole`, None unless the box lies inside the image."""
    H, W = image.shape[:2]
    x, y, w, h = box
    x0, y0, x1, y1 = round(x), round(y), round(x + w), round(y + h)
    if whole and (x0 < 0 or y0 < 0 or x1 > W or y1 > H):
        return None
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(W, x1), min(H, y1)
    if x1 - x0 < 4 or y1 - y0 < 4:
        return None
    return image[y0:y1, x0:x1]
