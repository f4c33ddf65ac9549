"""The paper (Contreras & Hitschfeld-Kahler): its classes, figures and notes as data, and the comparison."""

from .comparison import comparison_notes, paper_comparison, paper_study_key
from .published import paper_class, paper_classes, paper_notes, paper_studies

__all__ = ["comparison_notes", "paper_class", "paper_classes", "paper_comparison", "paper_notes", "paper_studies",
           "paper_study_key"]
