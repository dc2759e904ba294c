"""FE-vs-theory comparisons, verification studies, plots and reports."""
