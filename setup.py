"""Package list for setuptools (everything else is in pyproject.toml).

The prior files live once, in the top-level ``priors/`` folder of the repository, where a lab reads
and copies them; the wheel ships that folder inside the package as ``friction_uq/prior_files`` so that
an installed friction-uq finds them (:data:`friction_uq.priors.PRIORS_DIR`). A declarative
``packages.find`` cannot map a folder outside the package, hence this file.
"""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["friction_uq", "friction_uq.*"]), "friction_uq.prior_files"],
    package_dir={"friction_uq.prior_files": "priors"},
)
