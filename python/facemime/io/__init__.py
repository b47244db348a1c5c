"""Files in and out: video, images, output paths."""

from facemime.io.outputs import check_image_suffix, check_outputs, write_image
from facemime.io.video import VideoWriter

__all__ = ["VideoWriter", "check_image_suffix", "check_outputs", "write_image"]
