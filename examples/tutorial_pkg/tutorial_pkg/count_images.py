"""The /count_images service: how many image files a folder holds.

rosl service call /count_images tutorial_pkg/srv/CountImages "{folder_path: '/tmp'}"
"""

from pathlib import Path

import rclpy
from rclpy.node import Node

from tutorial_pkg.srv import CountImages

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tif", ".tiff", ".webp"}


class CountImagesServer(Node):
    def __init__(self):
        super().__init__("count_images")
        self.service = self.create_service(CountImages, "count_images", self.count)

    def count(self, request, response):
        folder = Path(request.folder_path).expanduser()
        if not folder.is_dir():
            response.count = 0
            response.message = f"not a folder: {request.folder_path}"
        else:
            images = [p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES]
            response.count = len(images)
            response.message = f"{len(images)} image(s) in {folder}"
        self.get_logger().info(response.message)
        return response


def main(args=None):
    rclpy.init(args=args)
    node = CountImagesServer()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
