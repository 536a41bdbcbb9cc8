"""Package discovery for the layout of the contract: engine/ is ``formgraph``, nodes/ is
``formgraph.nodes`` and viewer/ is ``formgraph.viewer`` (pyproject.toml maps the folders).

Every folder with an ``__init__.py`` under them is a package of the wheel, found here rather
than listed by hand, so a new sub-package can never be left out.
"""

from setuptools import find_packages, setup

ROOTS = {"formgraph": "engine", "formgraph.nodes": "nodes", "formgraph.viewer": "viewer"}

packages = []
for name, folder in ROOTS.items():
    packages.append(name)
    packages += [f"{name}.{sub}" for sub in find_packages(folder)]

setup(packages=packages)
