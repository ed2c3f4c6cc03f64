"""vnrrt: a fast, tested reproduction of VertexNet RRT* (vertex-based sampling for RRT*)."""

__version__ = "0.1.0"
