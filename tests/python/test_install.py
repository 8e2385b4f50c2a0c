"""`cmake --install` puts the module into the interpreter's site folder under the prefix
(DACRT_PYTHON_INSTALL_DIR), where that interpreter finds it: /usr/local's is on Debian's path."""
import os
import pathlib
import re
import subprocess
import sys
import sysconfig

import pytest


def build_dir():
    folder = os.environ.get("DACRT_BUILD_DIR")
    if not folder:
        pytest.skip("DACRT_BUILD_DIR names no build tree (ctest sets it)")
    return pathlib.Path(folder)


def test_the_installed_module_imports_from_the_site_folder(tmp_path):
    build = build_dir()
    cache = (build / "CMakeCache.txt").read_text()
    site = re.search(r"^DACRT_PYTHON_INSTALL_DIR:STRING=(.*)$", cache, re.M).group(1)
    subprocess.run(["cmake", "--install", str(build), "--component", "python", "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    installed = list(tmp_path.rglob("dacrt*.so"))
    assert [p.parent for p in installed] == [tmp_path / site]
    run = subprocess.run([sys.executable, "-c", "import dacrt; print(dacrt.__file__, dacrt.backends())"],
                         env={**os.environ, "PYTHONPATH": str(tmp_path / site)}, check=True, capture_output=True, text=True)
    assert run.stdout.startswith(str(installed[0]))
    # On Debian the default prefix's folder is one this interpreter reads (/usr/local/lib/python3.X/dist-packages).
    if "deb_system" in sysconfig.get_scheme_names():
        assert str(pathlib.Path("/usr/local") / site) in sys.path
