#!/usr/bin/env python3
"""Regenerates sim/builtin_plants.cpp from config/*.yaml.

Run from anywhere: python3 sim/gen_builtin_plants.py
tests/sim/test_scenarios.cpp fails when the copies and the files differ.
"""
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
FILES = [("kWoodBerry", "wood-berry.yaml"), ("kQuadTank", "quad-tank.yaml"),
         ("kQuadTank4x4", "quad-tank-4x4.yaml")]

out = ['#include "sim/builtin_plants.hpp"', "",
       "// Copies of config/wood-berry.yaml, config/quad-tank.yaml and",
       "// config/quad-tank-4x4.yaml, written by sim/gen_builtin_plants.py",
       "// (tests/sim/test_scenarios.cpp checks that the files and these copies",
       "// describe the same plants).",
       "namespace mpm::sim {", "namespace {", ""]
for name, file in FILES:
    text = (ROOT / "config" / file).read_text()
    assert ')yaml"' not in text, file
    out += ['constexpr std::string_view %s = R"yaml(%s)yaml";' % (name, text), ""]
out += ["}  // namespace", "",
        "std::optional<std::string_view> builtin_plant_text(std::string_view file_name) {"]
out += ['  if (file_name == "%s") return %s;' % (file, name) for name, file in FILES]
out += ["  return std::nullopt;", "}", "", "}  // namespace mpm::sim", ""]
(ROOT / "sim" / "builtin_plants.cpp").write_text("\n".join(out))
