# The documents: the tutorial's tables and code excerpts, the figure of
# plot_report.py, the Markdown of the repository, the size limits of its
# files.

# The error tables of doc/tutorial.md (made by doc/make_results.sh) are
# those of three runs above, to their printed digits. Catches: results
# that moved without the tutorial's tables made anew.
foreach(pair "case_m_quadrilateral;case-m-q1" "case_m_triangle;case-m-p1"
             "full_contact;full-contact-q1"
             "full_contact_triangle;full-contact-p1")
  list(GET pair 0 run)
  list(GET pair 1 block)
  add_test(NAME tutorial_table_${block}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/doc/results.py check
            ${CMAKE_SOURCE_DIR}/doc/tutorial.md ${block}
            ${CMAKE_CURRENT_BINARY_DIR}/${run}/report.csv)
  set_tests_properties(tutorial_table_${block} PROPERTIES
    FIXTURES_REQUIRED ${run})
endforeach()

# The table of the default run in doc/tutorial.md is that of a run of
# parameters/default.prm as shipped (14 adaptive cycles). Catches: a
# change of the default run's results that leaves the table behind.
membranes_scene_test(default_run default.prm SETTINGS Output/Write\ vtu=false)
add_test(NAME tutorial_table_default-run
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/doc/results.py check
          ${CMAKE_SOURCE_DIR}/doc/tutorial.md default-run
          ${CMAKE_CURRENT_BINARY_DIR}/default_run/report.csv)
set_tests_properties(tutorial_table_default-run PROPERTIES
  FIXTURES_REQUIRED default_run)

# The figure of source/plot_report.py: coinciding columns drawn once and
# named together, reference slopes in N (tests/check_plot_report.py).
# Catches: a curve hidden under another, slopes labelled in h on an axis
# of DoFs.
add_test(NAME plot_report
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_plot_report.py
          ${CMAKE_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/plot_report)
set_tests_properties(plot_report PROPERTIES LABELS quick)

# The code excerpts of the tutorial and of advanced.md are the program's
# code: each stands, in order, in the file its first line names. Catches:
# an excerpt that no longer matches the code it teaches.
add_test(NAME tutorial_excerpts
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_excerpts.py
          ${CMAKE_SOURCE_DIR}/doc/tutorial.md)
set_tests_properties(tutorial_excerpts PROPERTIES LABELS quick)
add_test(NAME advanced_excerpts
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_excerpts.py
          ${CMAKE_SOURCE_DIR}/doc/advanced.md)
set_tests_properties(advanced_excerpts PROPERTIES LABELS quick)

# The Markdown of the repository renders on GitHub: no control characters
# in any Markdown file, balanced math delimiters in the documents.
# Catches: a LaTeX backslash eaten by an escape, an unclosed $.
add_test(NAME markdown
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_markdown.py
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(markdown PROPERTIES LABELS quick)
# The same check on a file with the escapes that GitHub's Markdown takes out
# of math: it must name each of them. Catches: a check that lets them pass.
add_test(NAME markdown_escaped_math
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_markdown.py
          tests/markdown/escaped-math.md
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(markdown_escaped_math PROPERTIES LABELS quick
  PASS_REGULAR_EXPRESSION
  "md:1: '\\\\{' in inline math.*md:1: '\\\\}' in inline math.*md:1: '\\\\,' in inline math.*md:4: '\\\\\\\\' in display math")

# One meaning per symbol in doc/tutorial.md and doc/advanced.md
# (tests/check_symbols.py): no symbol in two rows of their symbol tables,
# none introduced again in the text ("with $X$ the ...", "$X$ denotes ...")
# with a meaning that shares no word with the table's. Catches: a symbol
# given a second meaning, or listed again by advanced.md.
add_test(NAME symbols
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_symbols.py
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(symbols PROPERTIES LABELS quick)
# The same check on copies of the documents with a duplicate row and a
# second meaning planted: it must report both. Catches: a check that lets
# them pass.
add_test(NAME symbols_planted
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/tests/check_symbols.py
          --planted
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(symbols_planted PROPERTIES LABELS quick)

# The size limits of the repository (tests/check_code_size.py): no file
# over 800 lines, no function of C++ or Python over 100 lines; it also
# prints the size of the library. Catches: a file or a function that grew
# past its limit.
add_test(NAME code_size
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_code_size.py
          ${CMAKE_SOURCE_DIR})
set_tests_properties(code_size PROPERTIES LABELS quick)
# The same check on a planted tree: a C++ and a Python function of 101
# lines and a file of 801 must be named, their twins of 100 and 800 not
# (tests/check_code_size_planted.py). Catches: a checker that lets them
# pass, or counts a line too many.
add_test(NAME code_size_planted
  COMMAND ${Python3_EXECUTABLE}
          ${CMAKE_CURRENT_SOURCE_DIR}/check_code_size_planted.py)
set_tests_properties(code_size_planted PROPERTIES LABELS quick)
