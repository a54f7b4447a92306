"""The Arduino library's two manifests, read as their tools read them: library.json by PlatformIO's
own manifest parser and schema, library.properties by the Arduino library specification's rules."""

from __future__ import annotations

import json
import re

import pytest

from protocol.generated.version import LICENSE, __version__
from protocol.generator import generate
from protocol.generator.emit import release

ROOT = generate.ROOT
# PlatformIO is a development tool (the `dev` extra), not one of the core packages' test needs: the
# other interpreters' runs (scripts/test_pythons.sh, the `test` extra) leave these out.
pytest.importorskip("platformio", reason="PlatformIO comes with the dev extra")


def test_platformio_reads_library_json() -> None:
    from platformio.package.manifest import schema
    from platformio.package.manifest.parser import ManifestFileType, ManifestParserFactory

    text = (ROOT / release.LIBRARY_JSON).read_text(encoding="utf-8")
    parser = ManifestParserFactory.new(text, ManifestFileType.LIBRARY_JSON)
    # The schema checks `license` against SPDX's list, which it fetches: offline, the one licence
    # the project names stands in for that list.
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(
            schema.ManifestSchema, "load_spdx_licenses", staticmethod(lambda: {"licenses": [{"licenseId": LICENSE}]})
        )
        manifest = schema.ManifestSchema().load_manifest(parser.as_dict())
    assert manifest["name"] == "RoverLink" and manifest["version"] == __version__
    assert manifest["frameworks"] == ["arduino"] and manifest["platforms"] == ["atmelavr"]
    assert manifest["headers"] == ["RoverLink.h"] and manifest["license"] == LICENSE
    assert "_" not in manifest  # the DO NOT EDIT line is not a field PlatformIO keeps
    assert json.loads(text)["_"].startswith("DO NOT EDIT: generated from protocol/spec/roverlink.toml")


def test_platformio_refuses_what_it_should() -> None:
    """The check above can fail: a version that is not semantic is refused."""
    from platformio.package.exception import ManifestValidationError
    from platformio.package.manifest import schema

    manifest = json.loads((ROOT / release.LIBRARY_JSON).read_text(encoding="utf-8"))
    manifest["version"] = "one"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(
            schema.ManifestSchema, "load_spdx_licenses", staticmethod(lambda: {"licenses": [{"licenseId": LICENSE}]})
        )
        with pytest.raises(ManifestValidationError, match="version"):
            schema.ManifestSchema().load_manifest(manifest)


def test_library_properties_follows_the_arduino_specification() -> None:
    lines = (ROOT / release.LIBRARY_PROPERTIES).read_text(encoding="utf-8").splitlines()
    fields = dict(line.split("=", 1) for line in lines if line and not line.startswith("#"))
    # Required by the Arduino library specification (1.5), but `url`, which needs the project's
    # public address.
    for key in ("name", "version", "author", "maintainer", "sentence", "paragraph", "category", "architectures"):
        assert fields.get(key), key
    assert fields["version"] == __version__
    assert re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9 _.-]*", fields["name"])
    assert fields["category"] in {
        "Display",
        "Communication",
        "Signal Input/Output",
        "Sensors",
        "Device Control",
        "Timing",
        "Data Storage",
        "Data Processing",
        "Other",
    }
    assert (ROOT / "arduino" / "RoverLink" / "src" / fields["includes"]).is_file()
