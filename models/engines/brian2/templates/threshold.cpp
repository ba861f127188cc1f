{# The engine's thresholder: the same events as Brian2's, found in two passes.

Brian2's thresholder tests every neuron with a branch that records it, a loop
the compiler cannot vectorise.  Spikes are rare, so this one first tests a
block of 64 neurons in a loop without stores (which vectorises) and runs the
recording loop only on the blocks where some neuron crossed.  The condition,
the recorded indices and their order are Brian2's.
#}
{# USES_VARIABLES { N } #}
{% extends 'common_group.cpp' %}
{% block maincode %}
    //// MAIN CODE ////////////
    // scalar code
    const int _vectorisation_idx = -1;
    {{scalar_code|autoindent}}

    {% set _eventspace = get_array_name(eventspace_variable) %}

    long _count = 0;
    for(size_t _block=0; _block<N; _block+=64)
    {
        const size_t _stop = _block + 64 < (size_t)N ? _block + 64 : (size_t)N;
        char _any = 0;
        for(size_t _idx=_block; _idx<_stop; _idx++)
        {
            const size_t _vectorisation_idx = _idx;
            {{vector_code|autoindent}}
            _any |= _cond;
        }
        if(!_any)
            continue;
        for(size_t _idx=_block; _idx<_stop; _idx++)
        {
            const size_t _vectorisation_idx = _idx;
            {{vector_code|autoindent}}
            if(_cond) {
                {{_eventspace}}[_count++] = _idx;
                {% if _uses_refractory %}
                {{not_refractory}}[_idx] = false;
                {{lastspike}}[_idx] = {{t}};
                {% endif %}
            }
        }
    }
    {{_eventspace}}[N] = _count;
{% endblock %}

{% block after_code %}
{% set _eventspace = get_array_name(eventspace_variable) %}
{{_eventspace}}[N] = 0;  // the event space has N+1 elements: the last holds the count
{% endblock %}
