"""The input of a multi-frame whole-system run: one stereo pair per camera frame, with its truth where known.

A :class:`FrameSequence` holds the pairs already fitted to the sensor (what the two sensor models output, frame
after frame) and, per frame, the ground truth when the input has one: the right image's disparity at every buffer
pixel (NaN = unknown) and the distance of what the centre of the right image shows (None = the background).

Three sources:

* :func:`sequence_from_folders`: two folders of images, paired in file-name order; one-line
  :class:`~sim.UserError` for an empty folder, different counts, a pair of different sizes, too few frames.
* :func:`sequence_from_videos`: two video files (anything OpenCV's FFmpeg reads: MP4, AVI, MKV, ...), frame k of
  each the pair of camera frame k; one-line :class:`~sim.UserError` for a file that is not a readable video,
  different frame counts or sizes, too few frames.
* :func:`repeated_pair`: one pair for every frame (a still scene).
* :func:`moving_card`: the synthetic test bed (``sim/testbed/scene.py``) with a textured card in front of the right
  camera moving from ``far_m`` to ``near_m`` over the run, evenly in 1/Z (so its disparity grows evenly);
  the card is the thesis's 19 cm rectangle at full size and its 5 cm x 4 cm small rectangle at the small size
  (the small sensor is the central 64 x 48 window of the full one: same pixel pitch and focal length, so its
  depth readout's distances are the full sensor's and its D = 8 codes cover 3.4 m and beyond).
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from golden.image_file import ImageFileError, image_size
from sim import UserError

__all__ = ["FrameSequence", "sequence_from_folders", "sequence_from_videos", "repeated_pair", "moving_card",
           "IMAGE_SUFFIXES", "VIDEO_SUFFIXES",
           "CARD_RANGE_M", "DROP",
           "offset_schedule"]

#: The file names a sequence folder's images may have.
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff")
#: The file names taken as video files (a LEFT/RIGHT pair of them is a sequence).
VIDEO_SUFFIXES = (".mp4", ".avi", ".mkv", ".mov", ".webm", ".m4v", ".mpg", ".mpeg")
#: A ``faults`` entry: the sensor drops that frame (its frame period has FV low; the image is never sent).
DROP = "drop"
#: Default (far, near) card distances in metres at the full and the small size: inside the depth engine's range
#: at each size, the 800 x 600 builds' included (twice the buffer disparity and twice the disparities).
CARD_RANGE_M = {"full": (3.0, 0.5), "small": (8.0, 4.0)}


@dataclass
class FrameSequence:
    """``pairs``: ``[(left, right), ...]`` RGB uint8 at the sensor's size, one per camera frame; ``truth``:
    per frame the right view's disparity in buffer pixels (NaN = unknown) or None; ``centre_m``: per frame the
    true distance at the centre of the right image or None; ``names``: per frame a label (file names, the card's
    distance); ``sources``: the input files (for provenance); ``faults``: per camera ``"a"``/``"b"`` a list with
    one entry per frame: None, a :class:`sim.models.mt9d112.sensor.Faults` for that frame, or :data:`DROP`;
    ``vertical_offsets``: per frame the rig's vertical offset in sensor rows when the input is rendered."""
    pairs: list
    truth: list = None
    centre_m: list = None
    names: list = None
    sources: list = field(default_factory=list)
    faults: dict = field(default_factory=dict)
    vertical_offsets: list = None       # per frame the rig's vertical offset in sensor rows (moving_card), or None

    def __post_init__(self):
        n = len(self.pairs)
        self.truth = self.truth if self.truth is not None else [None] * n
        self.centre_m = self.centre_m if self.centre_m is not None else [None] * n
        self.names = self.names if self.names is not None else [f"frame {k}" for k in range(n)]
        if not n or not len(self.truth) == len(self.centre_m) == len(self.names) == n:
            raise ValueError("a sequence has at least one pair and one truth, centre distance and name per pair")
        if any(c not in "ab" or len(f) != n for c, f in self.faults.items()):
            raise ValueError("faults: one list per camera 'a'/'b' with an entry per frame")

    def __len__(self):
        return len(self.pairs)

    def camera_faults(self, camera):
        """Camera ``camera``'s entry per frame (None, Faults or :data:`DROP`)."""
        return list(self.faults.get(camera, [None] * len(self)))

    def frames_sent(self, camera):
        """How many frames camera ``camera`` sends (those it does not drop)."""
        return sum(1 for f in self.camera_faults(camera) if f != DROP)

    def images(self, camera):
        """The images of camera ``"a"`` (left) or ``"b"`` (right), in order."""
        return [pair["ab".index(camera)] for pair in self.pairs]


def _image_files(folder, side):
    folder = Path(folder)
    if not folder.is_dir():
        raise UserError(f"{side} sequence: {folder} is not a folder")
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES)
    if not files:
        raise UserError(f"{side} sequence: no image files ({', '.join(IMAGE_SUFFIXES)}) in {folder}")
    return files


def sequence_from_folders(left_dir, right_dir, setup, frames=None):
    """The pairs of two folders (left = camera A, right = camera B), in file-name order, fitted to ``setup``'s
    sensor; the first ``frames`` of them (default all). One-line :class:`~sim.UserError` for bad input."""
    from golden.stereo_pair import load_pair
    left, right = _image_files(left_dir, "left"), _image_files(right_dir, "right")
    if len(left) != len(right):
        raise UserError(f"the left folder has {len(left)} images, the right folder {len(right)}: a sequence needs "
                        "one right image per left image")
    if frames is not None:
        if frames > len(left):
            raise UserError(f"--frames {frames}, but the folders hold {len(left)} pairs")
        left, right = left[:frames], right[:frames]
    g = setup.geometry
    sizes = set()
    pairs = []
    for lp, rp in zip(left, right):
        try:
            sizes.add(image_size(lp))
            pairs.append(load_pair(lp, rp, g.width, g.height, min_size=(g.buf_width, g.buf_height)))
        except (OSError, ValueError, ImageFileError) as exc:
            raise UserError(f"pair {lp.name} / {rp.name}: {exc}") from None
        if len(sizes) > 1:
            raise UserError(f"{lp.name} is {'x'.join(map(str, image_size(lp)))}, the sequence's first image "
                            f"{'x'.join(map(str, image_size(left[0])))}: all frames must have one size")
    return FrameSequence(pairs, names=[f"{lp.name} / {rp.name}" for lp, rp in zip(left, right)],
                         sources=[p for pair in zip(left, right) for p in pair])


def _video_frames(path, side, limit):
    """``(frames, count)``: the first ``limit`` frames of video ``path`` as RGB uint8 arrays (all when ``limit`` is
    None) and the number of frames it holds (read to the end when the container does not say)."""
    import cv2
    path = Path(path)
    if not path.is_file():
        raise UserError(f"{side} video: {path} does not exist")
    video = cv2.VideoCapture(str(path))
    try:
        if not video.isOpened():
            raise UserError(f"{side} video: {path} is not a video file OpenCV can read")
        frames = []
        while limit is None or len(frames) < limit:
            ok, bgr = video.read()
            if not ok:
                break
            frames.append(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB))
        count = int(video.get(cv2.CAP_PROP_FRAME_COUNT))
        if limit is None or count <= 0:
            count = len(frames) + sum(1 for _ in iter(lambda: video.grab(), False))
    finally:
        video.release()
    if not frames:
        raise UserError(f"{side} video: {path} holds no frame OpenCV can decode")
    return frames, count


def sequence_from_videos(left_path, right_path, setup, frames=None):
    """The pairs of two video files (left = camera A, right = camera B): frame k of each, fitted to ``setup``'s
    sensor; the first ``frames`` of them (default all). One-line :class:`~sim.UserError` for bad input."""
    left, n_left = _video_frames(left_path, "left", frames)
    right, n_right = _video_frames(right_path, "right", frames)
    if n_left != n_right:
        raise UserError(f"the left video has {n_left} frames, the right video {n_right}: a sequence needs one right "
                        "frame per left frame")
    if frames is not None and len(left) < frames:
        raise UserError(f"--frames {frames}, but the videos hold {len(left)} frames")
    size = lambda image: f"{image.shape[1]}x{image.shape[0]}"      # noqa: E731
    if size(left[0]) != size(right[0]):
        raise UserError(f"the left video is {size(left[0])}, the right video {size(right[0])}: both cameras' "
                        "frames must have one size")
    from golden.stereo_pair import check_crop
    g = setup.geometry
    try:
        check_crop(left[0].shape, g.width, g.height, (g.buf_width, g.buf_height))
    except ImageFileError as exc:
        raise UserError(f"the videos: {exc}") from None
    pairs = [(setup.fit(lf), setup.fit(rf)) for lf, rf in zip(left, right)]
    names = [f"{Path(left_path).name} / {Path(right_path).name} frame {k}" for k in range(len(pairs))]
    return FrameSequence(pairs, names=names, sources=[Path(left_path), Path(right_path)])


def repeated_pair(left, right, frames, setup, sources=()):
    """The pair ``left``/``right`` (RGB arrays, fitted to the sensor) for each of ``frames`` camera frames."""
    pair = (setup.fit(left), setup.fit(right))
    return FrameSequence([pair] * frames, sources=list(sources))


def card_rig(setup, vertical_offset_px=0.0):
    """The test bed's rig for ``setup``'s sensor (the VmodCAM; at the small size its central window), the left
    camera's image ``vertical_offset_px`` sensor rows lower than the right one's (``StereoRig``'s sign)."""
    from sim.testbed.scene import StereoRig
    g = setup.geometry
    return StereoRig(width=g.width, height=g.height, vertical_offset_px=vertical_offset_px)


def offset_schedule(frames, values):
    """Per camera frame the rig's vertical offset (sensor rows) for ``values`` ``[V1, V2, ...]``: the run split
    into ``len(values)`` equal parts (the later parts one frame shorter when it does not divide), part i at Vi;
    e.g. 6 frames of ``[0, 12]``: 0 0 0 12 12 12 (a knock to the rig before camera frame 3). One-line
    :class:`~sim.UserError` for more values than frames."""
    values = [0.0] if not values else list(values)
    if len(values) > frames:
        raise UserError(f"{len(values)} vertical offsets for {frames} camera frames: give at most one per frame")
    return [values[k * len(values) // frames] for k in range(frames)]


def card_distances(frames, far_m, near_m):
    """``frames`` distances from ``far_m`` to ``near_m``, evenly spaced in 1/Z."""
    if not (far_m > 0 and near_m > 0):
        raise UserError(f"card distances must be positive, not {far_m} m and {near_m} m")
    if frames == 1:
        return [float(far_m)]
    inv = np.linspace(1 / far_m, 1 / near_m, frames)
    return [float(1 / v) for v in inv]


def moving_card(setup, frames, far_m=None, near_m=None, vertical_offsets=None):
    """The synthetic test bed with the card moving from ``far_m`` to ``near_m`` over ``frames`` camera frames (see
    the module docstring; defaults :data:`CARD_RANGE_M`); ``vertical_offsets``: per frame the rig's vertical
    offset in sensor rows (:func:`offset_schedule`; default 0), a change between two frames a knock to the rig."""
    from sim.testbed.scene import object_footprint, rectangle, render_pair, small_rectangle
    size = "small" if setup.small_size else "full"
    default_far, default_near = CARD_RANGE_M[size]
    far_m = default_far if far_m is None else far_m
    near_m = default_near if near_m is None else near_m
    offsets = [0.0] * frames if vertical_offsets is None else list(vertical_offsets)
    if len(offsets) != frames:
        raise ValueError(f"{len(offsets)} vertical offsets for {frames} frames")
    make = rectangle if size == "full" else small_rectangle
    pairs, truth, centre, names = [], [], [], []
    g = setup.geometry
    for z, v in zip(card_distances(frames, far_m, near_m), offsets):
        rig = card_rig(setup, v)
        card = make(z, centre_x_m=rig.baseline_m / 2, finish="textured",
                    texel_m=0.01 if size == "full" else 0.004)
        pairs.append(render_pair(card, rig))
        # the card's disparity where the right camera's kept pixels see it (the background has no distance)
        t = np.full((g.buf_height, g.buf_width), np.nan)
        t[object_footprint(card, rig, side="right", scale=g.scale)] = rig.disparity_px(z) / g.scale
        truth.append(t)
        centre.append(z if np.isfinite(t[g.buf_height // 2, g.buf_width // 2]) else None)
        names.append(f"card at {z:.3f} m" + (f", rig vertical offset {v:+g} rows" if v else ""))
    return FrameSequence(pairs, truth=truth, centre_m=centre, names=names, vertical_offsets=offsets)
