"""Package discovery for hiconav's split layout.

The design keeps ``actors/``, ``trees/``, ``drivers/`` and ``config/`` at the top level while
they import as ``hiconav.actors`` and so on. setuptools' static ``package-dir`` table cannot
discover their subpackages, so they are listed here; all other metadata is in pyproject.toml.
"""

from setuptools import find_packages, setup

MAPPED = {"actors": "hiconav.actors", "trees": "hiconav.trees", "drivers": "hiconav.drivers",
          "config": "hiconav.config"}

packages = ["hiconav"] + [f"hiconav.{p}" for p in find_packages("hiconav")]
package_dir = {"hiconav": "hiconav"}
for folder, name in MAPPED.items():
    packages.append(name)
    package_dir[name] = folder
    for sub in find_packages(folder):
        packages.append(f"{name}.{sub}")
        package_dir[f"{name}.{sub}"] = f"{folder}/{sub.replace('.', '/')}"

setup(packages=packages, package_dir=package_dir)
