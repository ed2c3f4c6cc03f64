"""The configuration key: one written form, one parser, a round trip for every kind of key,
display names, order, and errors that name the bad text."""

import pytest

from vnrrt.config import ConfigError
from vnrrt.evaluation.keys import ConfigKey, label, sort_texts

SOURCES = {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star": "vertexnet"}
TEXTS = [
    "rrt_star",
    "nrrt_star",
    "vnrrt_star",
    "m_vnrrt_star@0.5",
    "m_vnrrt_star@0.99",
    "nrrt_star[oracle_path]",
    "vnrrt_star[oracle_vertex@q0.1]",
    "m_vnrrt_star@0.5[oracle_vertex]",
    "vnrrt_star[nrrtnet]",
    "rrt_star+informed",
    "m_vnrrt_star@0.9+informed",
    "vnrrt_star[oracle_vertex]+informed",
]


@pytest.mark.parametrize("text", TEXTS)
def test_every_key_round_trips(text):
    key = ConfigKey.parse(text, SOURCES)
    assert key.text == str(key) == text
    assert ConfigKey.parse(key.text, SOURCES) == key
    assert key.informed == text.endswith("+informed")


def test_a_protocol_key_samples_its_configured_source_and_a_named_one_its_own():
    assert ConfigKey.parse("vnrrt_star", SOURCES).source == "vertexnet"
    assert ConfigKey.parse("vnrrt_star", {"vnrrt_star": "other"}).source == "other"
    assert ConfigKey.parse("vnrrt_star").source is None  # unresolved without eval.sources
    named = ConfigKey.parse("vnrrt_star[oracle_vertex]", SOURCES)
    assert named.source == "oracle_vertex" and named.named_source
    assert ConfigKey.parse("rrt_star", SOURCES).source is None
    assert ConfigKey.parse("m_vnrrt_star@0.7").tau == 0.7


def test_with_source_and_informed_change_only_what_they_name():
    key = ConfigKey("m_vnrrt_star", 0.5, "vertexnet")
    assert key.with_source("oracle_vertex").text == "m_vnrrt_star@0.5[oracle_vertex]"
    assert key.with_informed().text == "m_vnrrt_star@0.5+informed"
    assert key.with_informed().with_informed(False) == key


def test_display_names_and_order():
    assert label("m_vnrrt_star@0.5") == "M-VNRRT* τ=0.5"
    assert label("vnrrt_star[oracle_vertex]") == "VNRRT* [oracle_vertex]"
    assert label("rrt_star+informed") == "Informed RRT*"
    assert label("nrrt_star+informed") == "informed NRRT*"
    texts = ["m_vnrrt_star@0.9", "rrt_star+informed", "vnrrt_star", "rrt_star",
             "m_vnrrt_star@0.5", "nrrt_star", "vnrrt_star[oracle_vertex]"]  # fmt: skip
    assert sort_texts(texts) == [
        "rrt_star",
        "nrrt_star",
        "vnrrt_star",
        "vnrrt_star[oracle_vertex]",
        "m_vnrrt_star@0.5",
        "m_vnrrt_star@0.9",
        "rrt_star+informed",
    ]
    assert ConfigKey.parse("m_vnrrt_star@0.5+informed").short == "m0.5_informed"
    assert ConfigKey.parse("m_vnrrt_star@0.5{max}[nrrtnet]").short == "m0.5_max_nrrtnet"


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("astar", "unknown planner"),
        ("m_vnrrt_star", "takes tau"),
        ("vnrrt_star@0.5", "takes tau"),
        ("m_vnrrt_star@x", "not a number"),
        ("vnrrt_star[oracle_vertex", "expected planner"),
        ("rrt_star[oracle_path]", "takes no heatmap"),
        ("vnrrt_star[]", "expected planner"),
    ],
)
def test_a_bad_key_is_refused_naming_it(text, why):
    with pytest.raises(ConfigError, match=why) as err:
        ConfigKey.parse(text)
    assert repr(text) in str(err.value)


@pytest.mark.parametrize(
    "text",
    ["vnrrt_star~0.25[oracle_vertex@s4]", "nrrt_star[oracle_blend@w0.5@s2]+free",
     "m_vnrrt_star@0.5{noends}~0.75[vertexnet]+free+informed", "rrt_star+free"],
)  # fmt: skip
def test_family_keys_round_trip(text):
    key = ConfigKey.parse(text, SOURCES)
    assert key.text == text and ConfigKey.parse(key.text, SOURCES) == key
    assert key.free == ("+free" in text) and (key.mix is None) == ("~" not in text)
