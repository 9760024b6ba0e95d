"""What the commands show: figures (`envelope_figure`, `labtest_figure`, `wind_figure`, `render`),
the report (`report`, with the paper's published numbers in `paper`) and the text of
`rawehelix orbits` (`orbits_report`).  Imports the post-processing and the store of
studies/, never a driver."""
