from glob import glob

from setuptools import setup

package_name = "lifecycle"

setup(
    name=package_name,
    version="0.20.0",
    packages=[package_name],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{package_name}"]),
        (f"share/{package_name}", ["package.xml"]),
        (f"share/{package_name}/launch", glob("launch/*.launch.py")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    entry_points={
        "console_scripts": [
            "lifecycle_talker = lifecycle.lifecycle_talker:main",
            "lifecycle_listener = lifecycle.lifecycle_listener:main",
            "lifecycle_service_client = lifecycle.lifecycle_service_client:main",
        ],
    },
)
