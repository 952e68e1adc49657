// api-docs.js — the interactive API page (GET /api?f=html): Swagger UI
// (web/swagger-ui-*, swagger-ui-dist, Apache-2.0; tools/vendor-swagger-ui.sh)
// over the service's own OpenAPI document.  Nothing is fetched from
// elsewhere: no validator badge (validatorUrl null), no CDN.
'use strict';
window.ui = window.SwaggerUIBundle({
  url: 'api',
  dom_id: '#swagger-ui',
  deepLinking: true,
  validatorUrl: null,
  presets: [window.SwaggerUIBundle.presets.apis],
  layout: 'BaseLayout',
});
