# Regenerates the standard scenes and fails if the committed JSON files differ.
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${SCENES} ${WORK} RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "downpour-scenes failed")
endif()
foreach(name highway_heavy_rain city_drizzle)
  file(READ ${WORK}/${name}.json generated)
  file(READ ${SOURCE}/${name}.json committed)
  if(NOT generated STREQUAL committed)
    message(FATAL_ERROR "clients/scenarios/${name}.json is stale: run build/downpour-scenes clients/scenarios")
  endif()
endforeach()

# The weather's fields (server/sim/weather.hpp): the Python client's module, and the table in the
# docs.
execute_process(COMMAND ${SCENES} --weather ${WORK}/weather_fields.py ${WORK}/weather.md
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "downpour-scenes --weather failed")
endif()
file(READ ${WORK}/weather_fields.py generated)
file(READ ${WEATHER_PY} committed)
if(NOT generated STREQUAL committed)
  message(FATAL_ERROR "${WEATHER_PY} is stale: run build/downpour-scenes --weather "
                      "clients/python/downpour_client/weather_fields.py /dev/stdout")
endif()
file(READ ${WORK}/weather.md table)
file(READ ${CONTRACT_DOC} doc)
string(FIND "${doc}" "${table}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "docs/contract.md's weather table differs from the definition:\n${table}")
endif()
