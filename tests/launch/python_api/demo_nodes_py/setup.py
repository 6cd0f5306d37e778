from glob import glob

from setuptools import setup

package_name = "demo_nodes_py"

setup(
    name=package_name,
    version="0.20.0",
    packages=[package_name, f"{package_name}.topics", f"{package_name}.services"],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{package_name}"]),
        (f"share/{package_name}", ["package.xml"]),
        (f"share/{package_name}/launch", glob("launch/*.launch.py")),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    entry_points={
        "console_scripts": [
            "talker = demo_nodes_py.topics.talker:main",
            "listener = demo_nodes_py.topics.listener:main",
            "add_two_ints_server = demo_nodes_py.services.add_two_ints_server:main",
            "add_two_ints_client = demo_nodes_py.services.add_two_ints_client:main",
        ],
    },
)
