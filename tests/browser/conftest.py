"""three.js tests in a real browser (engines/three): headless Chromium driven by playwright-core, WebGL2 on
SwiftShader.  Where node, the package's node modules or Chromium are missing they skip saying why; under CI
(CI=true, where .ci/run and scripts/env.sh install them) they fail instead."""
import os

import pytest


@pytest.fixture(scope="session")
def browser_ready():
    from rt_lookdev.validation.harness import three_browser

    why = three_browser.missing()
    if why:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{why} (CI installs it: .ci/run, scripts/env.sh)")
        pytest.skip(why)
    return three_browser
