"""Camera frames with capture times and dropped-frame counts, over one interface whatever the route.

    cam = CameraSource("picamera2")                          # Raspberry Pi camera on Raspberry Pi OS (picamera2)
    cam = CameraSource(0)                                    # /dev/video0, a USB webcam (V4L2, MJPG)
    cam = CameraSource("jetson-csi?flip=rotate-180")         # Jetson CSI camera (GStreamer, JetPack's OpenCV), turned
    cam = CameraSource("http://192.168.4.1:81/stream")       # ESP32-CAM, an IP camera, `roverlink emulate --camera`
    cam = CameraSource("run.mp4", fps=0)                     # a replay (a video file or an image folder)
    frame = cam.read()                                       # CameraFrame: BGR image, time_s, seq
    frames = cam.poll()                                      # every frame that arrived (streams: no wait)

The route comes from the source (`source.open_backend`), one module per backend: picamera2
(`picam`), OpenCV's V4L2, GStreamer and other URLs (`opencv`, GStreamer only where this OpenCV was
built with it: `pipelines`), MJPEG over HTTP and an emulator's `emudev://` byte stream with the
SDK's own parser (`stream`), and replays (`replay`). A route that cannot open says what is missing:
the module, the package to install, the device node, the permission.

`time_s` is when the frame was taken off the driver, on the source's clock (the host's monotonic
clock; an emulator's virtual clock in-process). Dropped frames are counted from the stream's frame
counter when it has one (`X-Frame`), otherwise from gaps longer than 1.5 frame periods.
"""

from host_sdk.sensors.camera.frame import CameraFrame
from host_sdk.sensors.camera.pipelines import FLIPS, PIPELINES, gstreamer_pipeline
from host_sdk.sensors.camera.source import SOURCES, CameraSource

__all__ = ["FLIPS", "PIPELINES", "SOURCES", "CameraFrame", "CameraSource", "gstreamer_pipeline"]
