"""Reports: sections of text, tables and figures, written as one self-contained HTML file."""

from .html import Report as Report
from .html import Section as Section

__all__ = ["Report", "Section"]
