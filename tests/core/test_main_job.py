"""The main job's report (validation/main_job.py) is written from real step results: every section, with
the render steps skipped and with them present."""
from rt_lookdev.core.lut import catalog
from rt_lookdev.validation import main_job


def test_report_is_written_from_the_steps(tmp_path, monkeypatch):
    monkeypatch.setattr(main_job, "LTC_LIGHTS", (6, 3))        # a small seeded light set: the same code path
    monkeypatch.setattr(main_job, "HORIZON_LIGHTS", (6, 4))
    quiet = lambda *a: None                                     # noqa: E731
    job = {"date": "today", "seconds": 1.0,
           "luts": main_job.step_luts(catalog.default_lut_dir(), quiet),
           "numpy_checks": main_job.step_numpy_checks(catalog.default_lut_dir(), quiet),
           "ltc": main_job.step_ltc(catalog.default_lut_dir(), quiet),
           "render": None, "demo": None, "lookdev_twin": None, "validation": None, "world_validation": None,
           "speed_error": None}
    job["passed"] = main_job._passed(job)
    main_job.write_report(job, tmp_path / "skipped")
    text = (tmp_path / "skipped" / "report.md").read_text()
    assert text.count("Skipped (--skip-render).") == 6 and "## LTC area lights" in text
    # the lights at the horizon, crossing and above apart, Lambert's exact horizon gated (issue 30)
    assert "### At the horizon" in text and "| disk/crossing | 6 |" in text and "| ggx/quad/above |" in text
    for kind in ("quad", "disk"):
        exact = job["ltc"]["horizon"]["lambert"][f"{kind}/crossing"]["exact horizon"]
        assert exact["rel_max"] < main_job.HORIZON_LAMBERT_TOL, kind
    assert (tmp_path / "skipped" / "report.json").stat().st_size > 0
    job["render"] = {"settings": {"resolution_per_sphere": 8, "samples": 4, "seeds": [0, 1], "z_max": 5.0,
                                  "sys_tol": 5e-4, "ms_tol": 0.005}, "summary_markdown": "RENDER TABLE",
                     "passed": True}
    for step in ("lut_export", "demo", "lookdev_twin", "realtime_benchmark", "validation", "world_validation",
                 "robustness", "speed_error"):
        job[step] = {"summary_markdown": f"{step.upper()} TABLE", "passed": True}
    main_job.write_report(job, tmp_path / "full")
    text = (tmp_path / "full" / "report.md").read_text()
    assert all(f"{s} TABLE" in text for s in ("RENDER", "LUT_EXPORT", "DEMO", "LOOKDEV_TWIN", "REALTIME_BENCHMARK", "VALIDATION",
                                              "WORLD_VALIDATION", "ROBUSTNESS", "SPEED_ERROR"))
    assert "Skipped" not in text
    assert "quick forms of the validation suite" in text and "--full" in text     # the report says what ran
    job["mode"], job["step_seconds"] = "full", {"luts": 1.5, "ltc": 18.3}
    main_job.write_report(job, tmp_path / "whole")
    text = (tmp_path / "whole" / "report.md").read_text()
    assert "`bash scripts/main.sh --full`" in text and "| ltc | 18.3 |" in text


def test_quick_by_default_and_whole_with_full():
    assert not main_job.parse_args([]).full and main_job.parse_args(["--full"]).full
