"""Figures and the PDF report. Pages only draw data computed upstream (summarise, then render)."""
